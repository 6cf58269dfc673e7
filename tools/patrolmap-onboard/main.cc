// patrolmap-onboard: maps live, from a camera or a log replayed at its real rate (DESIGN.md, front ends).
// The flow stage runs on the frame thread, place recognition on a worker behind a bounded queue; SIGINT and
// SIGTERM stop the stream and the map is written (atomically) as if it had ended.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "../cli_checks.h"
#include "patrolmap/core/files.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/pipeline/onboard.h"

namespace patrolmap::onboard {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> stop_requested{false};

void RequestStop(int) { stop_requested.store(true); }

struct Arguments {
  std::string source;
  std::string prior_map;
  std::string out = "patrolmap_onboard";
  std::string config;
  std::string vocabulary;  // empty: the default one
  double fps = 0.0;
  bool fast = false;
  double max_seconds = 0.0;
  pipeline::OnboardOptions options;
};

Status OpenSource(const Arguments& arguments, const pipeline::Config& config,
                  std::unique_ptr<io::FrameSource>* source) {
  const std::string prefix = "camera:";
  if (arguments.source.rfind(prefix, 0) != 0) return io::OpenLog(arguments.source, config.input, source);
  try {
    return io::OpenCamera(std::stoi(arguments.source.substr(prefix.size())), config.input, source);
  } catch (const std::exception&) {
    return Status::InvalidArgument(arguments.source + ": expected camera:N with a device number N");
  }
}

// How the stream went: wall time and how far behind the log's clock the frame thread fell.
struct Pace {
  double seconds = 0.0;
  double max_lag_seconds = 0.0;
  bool interrupted = false;
};

// Feeds the stream to the mapper until it ends, --max-seconds of it have passed or a stop is requested;
// a log is replayed at its own rate unless --fast.
Status Stream(const Arguments& arguments, io::FrameSource* source, pipeline::OnboardMapper* mapper, Pace* pace) {
  const bool paced = !arguments.fast && source->info().kind != "camera";
  const Clock::time_point start = Clock::now();
  Clock::time_point last_report = start;
  Frame frame;
  Status status;
  std::optional<TimestampNs> first_ns;
  while (!stop_requested.load() && (status = source->Next(mapper->NeedsImage(), &frame)).ok()) {
    if (!first_ns) first_ns = frame.timestamp_ns;
    const double flight_s = NsToSeconds(frame.timestamp_ns - *first_ns);
    if (arguments.max_seconds > 0.0 && flight_s > arguments.max_seconds) break;
    const Clock::time_point due =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(flight_s));
    if (paced) std::this_thread::sleep_until(due);
    PATROLMAP_RETURN_IF_ERROR(mapper->AddFrame(frame));
    if (paced)
      pace->max_lag_seconds =
          std::max(pace->max_lag_seconds, std::chrono::duration<double>(Clock::now() - due).count());
    if (Clock::now() - last_report > std::chrono::seconds(5)) {
      last_report = Clock::now();
      spdlog::info("{:.0f} s of flight, {} frames, {} key frames", flight_s, mapper->stats().frames,
                   mapper->stats().key_frames);
    }
  }
  pace->interrupted = stop_requested.load();
  pace->seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return status.ok() || status.end_of_stream() ? Status::Ok() : status;
}

void PrintSummary(const Arguments& arguments, const pipeline::OnboardStats& s, const pipeline::MapResult& result,
                  const Pace& pace) {
  std::printf(
      "%s%lld frames in %.1f s (%.1f frames/s), %lld processed: flow %.2f ms per processed frame (slowest "
      "%.1f ms); %d key frames (%d lost from the ring), %zu nodes, %zu loop closures; place queue at most "
      "%d deep, frame thread waited %.2f s for it, fell at most %.3f s behind the log's clock; outputs in %s\n",
      pace.interrupted ? "interrupted: " : "", static_cast<long long>(s.frames), pace.seconds,
      pace.seconds > 0 ? s.frames / pace.seconds : 0.0, static_cast<long long>(s.processed),
      s.processed ? 1e3 * s.flow_seconds / s.processed : 0.0, 1e3 * s.max_flow_seconds, s.key_frames, s.lost_key_frames,
      result.nodes.size(), result.loop_closures.size(), s.max_queue, s.waited_seconds, pace.max_lag_seconds,
      arguments.out.c_str());
}

// The patrol record of a flight mapped onboard: no objects or evidence grid (they need the whole log), but
// the camera and the width its key-frame features were found at, which a later `patrolmap patrol` or `diff`
// needs to compare the flight's key frames.
PatrolRecord AppearanceRecord(const io::LogInfo& info, const pipeline::MapResult& result) {
  PatrolRecord record;
  record.flight = info.flight_id;
  if (info.camera) record.camera = *info.camera;
  record.feature_image_width = pipeline::FeatureWidth(result, info.flight_id);
  return record;
}

Status Run(const Arguments& arguments) {
  pipeline::Config config;
  if (arguments.source.rfind("camera:", 0) != 0) {
    PATROLMAP_RETURN_IF_ERROR(io::CheckLogExists(arguments.source));
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInput(arguments.out, arguments.source, "flight log"));
  }
  PATROLMAP_RETURN_IF_ERROR(pipeline::LoadCheckedConfig(arguments.config, &config));
  if (arguments.fps > 0.0) config.input.frame_rate_hz = arguments.fps;
  std::string error;
  if (!arguments.options.IsValid(&error)) return Status::InvalidArgument(error);
  graph::TopoMap prior;
  if (!arguments.prior_map.empty()) {
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInput(arguments.out + "/map.pmap", arguments.prior_map, "prior map"));
    PATROLMAP_RETURN_IF_ERROR(graph::LoadMap(arguments.prior_map, &prior));
  }
  vocab::Vocabulary vocabulary;
  std::string vocabulary_path;
  PATROLMAP_RETURN_IF_ERROR(pipeline::LoadSiftVocabulary(arguments.vocabulary, &vocabulary, &vocabulary_path));
  PATROLMAP_RETURN_IF_ERROR(pipeline::CheckVocabulary(prior, arguments.prior_map, vocabulary, vocabulary_path));
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(OpenSource(arguments, config, &source));
  place::PlaceRecognizer recognizer(&vocabulary, config.place);
  PATROLMAP_RETURN_IF_ERROR(pipeline::SeedRecognizer(prior, arguments.prior_map, vocabulary, &recognizer));
  pipeline::MapResult result;
  Pace pace;
  {
    pipeline::OnboardMapper mapper(config, source->info(), &recognizer, arguments.options);
    PATROLMAP_RETURN_IF_ERROR(Stream(arguments, source.get(), &mapper, &pace));
    if (pace.interrupted) spdlog::info("stop requested: writing the map");
    PATROLMAP_RETURN_IF_ERROR(mapper.Finish(&result));
    PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(arguments.out));
    PATROLMAP_RETURN_IF_ERROR(
        WriteFileAtomically(arguments.out + "/key_locations.csv", pipeline::KeyLocationsCsv(mapper.key_locations())));
    graph::TopoMap map = pipeline::BuildTopoMap(result, recognizer, &prior);
    map.set_vocabulary(pipeline::TagOf(vocabulary, vocabulary_path));
    if (!result.nodes.empty()) map.SetPatrol(AppearanceRecord(source->info(), result));
    PATROLMAP_RETURN_IF_ERROR(pipeline::SaveMapRun(&map, arguments.out));
    PrintSummary(arguments, mapper.stats(), result, pace);
  }
  return Status::Ok();
}

}  // namespace
}  // namespace patrolmap::onboard

int main(int argc, char** argv) {
  using patrolmap::onboard::Arguments;
  Arguments arguments;
  CLI::App app{"patrolmap-onboard: maps live from a camera or a flight log replayed at its real rate"};
  app.set_version_flag("--version", "patrolmap-onboard 0.1.0");
  bool quiet = false;
  app.add_option("source", arguments.source, "a flight log (any form patrolmap map reads) or camera:N")->required();
  app.add_option("--map", arguments.prior_map, "map of earlier flights to close loops against (map.pmap)");
  app.add_option("-o,--out", arguments.out, "output folder: map.pmap, nodes.csv, loop_closures.csv, key_locations.csv")
      ->capture_default_str();
  app.add_option("-c,--config", arguments.config, "YAML configuration (see config/default.yaml)");
  app.add_option("--vocabulary", arguments.vocabulary, "vocabulary file (default: the shipped one)");
  app.add_option("--fps", arguments.fps, "frame rate of a log without timestamps [Hz] (default: its own times)")
      ->check(patrolmap::tools::FiniteRange(0.001, 10000.0));
  app.add_flag("--fast", arguments.fast, "replay a log as fast as it can be processed, not at its own rate");
  app.add_option("--max-seconds", arguments.max_seconds, "stop after this much of the flight [s]; 0: at its end")
      ->check(patrolmap::tools::FiniteRange(0.0));
  app.add_flag(
      "--inline-places", [&arguments](std::int64_t) { arguments.options.place_worker = false; },
      "run place recognition on the frame thread (the map is the same)");
  app.add_option("--queue", arguments.options.queue_capacity, "key frames waiting for place recognition at most")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--ring-s", arguments.options.ring_s,
                 "seconds of processed frames kept for key locations confirmed late")
      ->capture_default_str()
      ->check(patrolmap::tools::FiniteRange(0.1, 3600.0));
  app.add_flag("-q,--quiet", quiet, "only print errors");
  app.footer("SIGINT or SIGTERM ends the stream; the map is written as if it had ended, and the exit code is 0.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  }
  spdlog::set_default_logger(spdlog::stderr_logger_mt("patrolmap-onboard"));
  spdlog::set_pattern("%l: %v");
  spdlog::set_level(quiet ? spdlog::level::err : spdlog::level::info);
  std::signal(SIGINT, patrolmap::onboard::RequestStop);
  std::signal(SIGTERM, patrolmap::onboard::RequestStop);
  const patrolmap::Status status = patrolmap::onboard::Run(arguments);
  if (!status.ok()) {
    spdlog::error("{}", status.message());
    return 1;
  }
  return 0;
}
