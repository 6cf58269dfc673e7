// patrolmap detect LOG [--config FILE] [--out DIR]
#include <cstdio>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/files.h"
#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/detect.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct DetectArguments {
  std::string log;
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
  std::string out = "patrolmap_out";
  std::string quantity;
  std::string smoothing;
  double fps = 0.0;
  std::vector<std::string> topics;
};

Status ApplyOverrides(const DetectArguments& arguments, pipeline::Config* config) {
  if (!arguments.quantity.empty() &&
      !flow::ParseResponseQuantity(arguments.quantity, &config->flow.response.quantity)) {
    return Status::InvalidArgument("--response must be length or line_parameter");
  }
  if (!arguments.smoothing.empty() && !flow::ParseSmoothingMode(arguments.smoothing, &config->flow.smoothing.mode)) {
    return Status::InvalidArgument("--smoothing must be centered or causal");
  }
  return Status::Ok();
}

void PrintSummary(const DetectArguments& arguments, const pipeline::DetectionResult& result) {
  int peaks = 0;
  for (const KeyLocation& node : result.key_locations) peaks += node.kind == ExtremumKind::kPeak;
  std::printf(
      "%s: %lld frames, %zu processed, %zu key locations (%d peaks, %zu valleys), %zu unreadable frames "
      "skipped, %.1f s (%.0f frames/s); outputs in %s\n",
      arguments.log.c_str(), static_cast<long long>(result.frames_read), result.samples.size(),
      result.key_locations.size(), peaks, result.key_locations.size() - peaks, result.skipped.size(), result.seconds,
      result.frames_read / std::max(result.seconds, 1e-9), arguments.out.c_str());
}

int RunDetect(const DetectArguments& arguments) {
  pipeline::Config config;
  Status status = io::CheckLogExists(arguments.log);
  if (status.ok()) status = RefuseOverwritingInput(arguments.out, arguments.log, "flight log");
  if (status.ok()) status = LoadCheckedConfig(arguments.config, arguments.settings, &config);
  if (status.ok()) status = ApplyOverrides(arguments, &config);  // command-line flags win over the file
  if (status.ok() && arguments.fps > 0.0) config.input.frame_rate_hz = arguments.fps;
  if (status.ok()) status = io::ParseTopicChoice(arguments.topics, &config.input.topics);
  if (!status.ok()) return Fail(status);
  std::unique_ptr<io::FrameSource> source;
  status = io::OpenLog(arguments.log, config.input, &source);
  if (!status.ok()) return Fail(status);
  pipeline::DetectionResult result;
  {
    Progress progress("detect");
    status =
        pipeline::RunDetection(source.get(), config.flow, &result,
                               [&progress](std::int64_t done, std::int64_t total) { progress.Update(done, total); });
  }
  if (!status.ok()) return Fail(status);
  for (const std::string& warning : pipeline::DetectionWarnings(source->info(), result, config.flow)) {
    spdlog::warn("{}", warning);
  }
  if (config.flow.response.derotate_with_imu && !result.derotated && source->info().has_imu) {
    spdlog::warn("{}: IMU present but camera extrinsics unknown: flow not de-rotated", arguments.log);
  }
  status = pipeline::WriteDetectionOutputs(result, arguments.out,
                                           pipeline::LoadPlotTruth(arguments.log, result.key_locations));
  if (!status.ok()) return Fail(status);
  PrintSummary(arguments, result);
  return 0;
}

}  // namespace

Command AddDetectCommand(CLI::App* app) {
  auto arguments = std::make_shared<DetectArguments>();
  app->add_option("log", arguments->log,
                  "flight log: EuRoC folder, image folder, printf pattern (frame_%04d.png) or video file")
      ->required();
  app->add_option("-c,--config", arguments->config, "YAML configuration (see config/default.yaml)");
  AddSetOption(app, &arguments->settings);
  app->add_option("-o,--out", arguments->out, "output folder")->capture_default_str();
  app->add_option("--response", arguments->quantity, "override flow.response.quantity: length or line_parameter");
  app->add_option("--smoothing", arguments->smoothing, "override flow.smoothing.mode: centered or causal");
  AddFpsOption(app, &arguments->fps);
  AddTopicOption(app, &arguments->topics);
  app->footer("Writes OUT/key_locations.csv, OUT/response.csv and OUT/response.svg.");
  return [arguments] { return RunDetect(*arguments); };
}

}  // namespace patrolmap::tools
