// patrolmap map LOG [LOG ...] --out DIR [--config FILE] [--vocabulary FILE] [--every-frame]
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/files.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/pipeline/change.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/pipeline/flight_pass.h"
#include "patrolmap/pipeline/map.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct MapArguments {
  std::vector<std::string> logs;
  std::string prior_map;  // patrol: the map the flight extends
  std::string out = "patrolmap_map";
  std::string config;
  std::string vocabulary;  // empty: the default one (pipeline::FindDefaultVocabulary)
  double fps = 0.0;        // rate of logs without timestamps (0: their own)
  bool every_frame = false;
};

// What the patrol record of a flight holds, on the log.
void LogRecord(const pipeline::FlightResult& flight) {
  const PatrolRecord& record = flight.record;
  const pipeline::PatrolRecordStats& stats = flight.record_stats;
  if (record.has_objects) {
    const auto confirmed =
        std::count_if(record.objects.begin(), record.objects.end(), [](const MapObject& o) { return o.confirmed; });
    spdlog::info("{}: {} objects ({} more seen too rarely) from {} detections ({:.3f} ms per association)",
                 record.flight, confirmed, record.objects.size() - static_cast<std::size_t>(confirmed),
                 stats.detections, stats.associations ? 1e3 * stats.association_seconds / stats.associations : 0.0);
  }
  if (record.grid.voxel_size > 0) {
    spdlog::info("{}: evidence grid of {} voxels from {} depth frames in {:.1f} s", record.flight,
                 record.grid.voxels.size(), stats.depth_frames, stats.grid_seconds);
  }
}

// One flight through the per-frame pass: its nodes and loop closures into `result`, its patrol record into
// `record`, and its detect outputs to OUT, or to OUT/<flight> when several logs are mapped together.
Status MapFlight(const MapArguments& arguments, const std::string& log, const pipeline::Config& config,
                 place::PlaceRecognizer* recognizer, pipeline::MapResult* result, PatrolRecord* record) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(log, config.input, &source));
  if (arguments.every_frame && !source->info().timed) {
    spdlog::warn(
        "{}: no timestamps: every image is a node, and images at most place.exclude_recent_images = {} before a "
        "query are not its candidates",
        log, config.place.exclude_recent_images);
  }
  pipeline::FlightPassOptions options;
  options.node_every = arguments.every_frame ? 1 : 0;
  options.keep_samples = !arguments.every_frame;
  Progress progress("map");
  pipeline::DriveOptions drive;
  drive.progress = [&progress](std::int64_t done, std::int64_t total) { progress.Update(done, total); };
  pipeline::FlightRun run;
  PATROLMAP_RETURN_IF_ERROR(
      pipeline::RunFlight(source.get(), config, options, drive, recognizer, result, nullptr, &run));
  for (const std::string& warning : run.warnings) spdlog::warn("{}", warning);
  LogRecord(run.result);
  *record = std::move(run.result.record);
  if (arguments.every_frame) return Status::Ok();
  const bool several = arguments.logs.size() > 1;
  return pipeline::WriteDetectionOutputs(run.result.detection,
                                         several ? arguments.out + "/" + source->info().flight_id : arguments.out);
}

void PrintSummary(const MapArguments& arguments, const pipeline::MapResult& result) {
  const double nodes = std::max<std::size_t>(1, result.nodes.size());
  std::printf(
      "%zu log(s): %zu nodes, %zu loop closures; per key frame %.1f ms features, %.2f ms query, %.1f ms "
      "verification, %.2f ms database update; outputs in %s\n",
      arguments.logs.size(), result.nodes.size(), result.loop_closures.size(), 1e3 * result.seconds_features / nodes,
      1e3 * result.seconds_query / nodes, 1e3 * result.seconds_verify / nodes, 1e3 * result.seconds_add / nodes,
      arguments.out.c_str());
}

// The change report between the prior map's last flight and the new one.
Status ReportChanges(const graph::TopoMap& prior, const graph::TopoMap& map, const pipeline::Config& config,
                     const std::string& out) {
  change::ChangeReport report;
  bool compared = false;
  PATROLMAP_RETURN_IF_ERROR(pipeline::ReportLastFlight(prior, map, config.change, out, &report, &compared));
  if (compared) PrintChangeSummary(report, out);
  return Status::Ok();
}

int RunMap(const MapArguments& arguments) {
  pipeline::Config config;
  vocab::Vocabulary vocabulary;
  graph::TopoMap prior;
  Status status;
  for (const std::string& log : arguments.logs) {
    if (status.ok()) status = io::CheckLogExists(log);  // a missing log first: it is the likeliest mistake
    if (status.ok()) status = RefuseOverwritingInput(arguments.out, log, "flight log");
  }
  if (status.ok() && !arguments.prior_map.empty()) {
    status = RefuseOverwritingInput(arguments.out + "/map.pmap", arguments.prior_map, "prior map");
  }
  if (status.ok()) status = LoadCheckedConfig(arguments.config, &config);
  if (status.ok() && arguments.fps > 0.0) config.input.frame_rate_hz = arguments.fps;
  if (status.ok() && !arguments.prior_map.empty()) status = graph::LoadMap(arguments.prior_map, &prior);
  std::string vocabulary_path;
  if (status.ok()) status = pipeline::LoadSiftVocabulary(arguments.vocabulary, &vocabulary, &vocabulary_path);
  if (status.ok()) status = pipeline::CheckVocabulary(prior, arguments.prior_map, vocabulary, vocabulary_path);
  if (!status.ok()) return Fail(status);
  place::PlaceRecognizer recognizer(&vocabulary, config.place);
  status = pipeline::SeedRecognizer(prior, arguments.prior_map, vocabulary, &recognizer);
  if (!status.ok()) return Fail(status);
  pipeline::MapResult result;
  std::vector<PatrolRecord> records(arguments.logs.size());
  for (std::size_t i = 0; status.ok() && i < arguments.logs.size(); ++i) {
    status = MapFlight(arguments, arguments.logs[i], config, &recognizer, &result, &records[i]);
  }
  graph::TopoMap map = pipeline::BuildTopoMap(result, recognizer, &prior);
  map.set_vocabulary(pipeline::TagOf(vocabulary, vocabulary_path));
  for (PatrolRecord& record : records) {
    if (status.ok()) map.SetPatrol(std::move(record));
  }
  // The change report first: the map file, which may replace an earlier one, is written last, once
  // everything else has succeeded.
  if (status.ok() && !arguments.prior_map.empty()) status = ReportChanges(prior, map, config, arguments.out);
  if (status.ok()) status = pipeline::SaveMapRun(&map, arguments.out);
  if (!status.ok()) return Fail(status);
  PrintSummary(arguments, result);
  return 0;
}

}  // namespace

Command AddPatrolCommand(CLI::App* app) {
  auto arguments = std::make_shared<MapArguments>();
  arguments->out = "patrolmap_patrol";
  app->add_option("log", arguments->logs, "the new flight's log")->required()->expected(1);
  app->add_option("--map", arguments->prior_map, "the map of earlier flights (map.pmap)")->required();
  app->add_option("-o,--out", arguments->out, "output folder")->capture_default_str();
  app->add_option("-c,--config", arguments->config, "YAML configuration (see config/default.yaml)");
  app->add_option("--vocabulary", arguments->vocabulary, "vocabulary file (default: the shipped one)");
  AddFpsOption(app, &arguments->fps);
  app->footer(
      "Closes loops of the new flight against every earlier flight of the map and writes the extended map to "
      "OUT/map.pmap, the new nodes and loop closures to OUT/nodes.csv and OUT/loop_closures.csv, and what changed "
      "since the map's last flight to OUT/changes.json and OUT/changes.html (as patrolmap diff).");
  return [arguments] { return RunMap(*arguments); };
}

Command AddMapCommand(CLI::App* app) {
  auto arguments = std::make_shared<MapArguments>();
  app->add_option("logs", arguments->logs,
                  "flight log(s) as for detect; several are matched in order through one "
                  "database, so later flights close loops against earlier ones")
      ->required();
  app->add_option("-o,--out", arguments->out, "output folder")->capture_default_str();
  app->add_option("-c,--config", arguments->config, "YAML configuration (see config/default.yaml)");
  app->add_option("--vocabulary", arguments->vocabulary,
                  "vocabulary file (patrolmap vocab build; default: the shipped one, found beside the program, in "
                  "the install prefix or at $PATROLMAP_VOCABULARY)");
  AddFpsOption(app, &arguments->fps);
  app->add_flag("--every-frame", arguments->every_frame,
                "make every image a node, without key-location detection (image collections, place recognition "
                "alone); without timestamps 'recent' is counted in images (place.exclude_recent_images)");
  app->footer(
      "Writes OUT/map.pmap, OUT/nodes.csv and OUT/loop_closures.csv, and the detect outputs unless --every-frame.");
  return [arguments] { return RunMap(*arguments); };
}

}  // namespace patrolmap::tools
