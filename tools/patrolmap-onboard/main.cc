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
#include "patrolmap/pipeline/change.h"
#include "patrolmap/pipeline/change_events.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/pipeline/flight_pass.h"

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
  pipeline::FlightPassOptions options;
  pipeline::ChangeEventOptions events;
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

void PrintSummary(const Arguments& arguments, const pipeline::FlightRun& run, const pipeline::MapResult& result) {
  const pipeline::FlightPassStats& s = run.result.stats;
  const pipeline::DriveResult& pace = run.drive;
  std::printf(
      "%s%lld frames in %.1f s (%.1f frames/s), %lld processed: flow %.2f ms per processed frame (slowest "
      "%.1f ms); %d key frames (%d lost from the ring), %zu nodes, %zu loop closures; place queue at most %d "
      "deep, change queue %d, frame thread waited %.2f s for them, fell at most %.3f s behind the log's clock; "
      "outputs in %s\n",
      pace.interrupted ? "interrupted: " : "", static_cast<long long>(s.frames), pace.seconds,
      pace.seconds > 0 ? s.frames / pace.seconds : 0.0, static_cast<long long>(s.processed),
      s.processed ? 1e3 * s.flow_seconds / s.processed : 0.0, 1e3 * s.max_flow_seconds, s.key_frames, s.lost_key_frames,
      result.nodes.size(), result.loop_closures.size(), s.place_queue.max_depth, s.change_queue.max_depth,
      s.place_queue.waited_seconds + s.change_queue.waited_seconds, pace.max_lag_seconds, arguments.out.c_str());
}

// Opens DIR/events.jsonl when there is a prior flight to compare with.
Status OpenMonitor(const Arguments& arguments, const graph::TopoMap& prior, const pipeline::Config& config,
                   std::unique_ptr<pipeline::ChangeMonitor>* monitor) {
  const std::vector<std::string> flights = prior.Flights();
  if (flights.empty()) return Status::Ok();
  return pipeline::ChangeMonitor::Open(&prior, flights.back(), config, arguments.events,
                                       arguments.out + "/events.jsonl", monitor);
}

// The flight's map, its change report against the prior's last flight, and the final events.
Status WriteOutputs(const Arguments& arguments, const pipeline::Config& config, const graph::TopoMap& prior,
                    const pipeline::MapResult& result, const place::PlaceRecognizer& recognizer,
                    const graph::TopoMap::VocabularyTag& tag, pipeline::FlightRun* run,
                    pipeline::ChangeMonitor* monitor) {
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(arguments.out + "/key_locations.csv",
                                                pipeline::KeyLocationsCsv(run->result.detection.key_locations)));
  graph::TopoMap map = pipeline::BuildTopoMap(result, recognizer, &prior);
  map.set_vocabulary(tag);
  if (!result.nodes.empty()) map.SetPatrol(std::move(run->result.record));
  change::ChangeReport report;
  bool compared = false;
  PATROLMAP_RETURN_IF_ERROR(pipeline::ReportLastFlight(prior, map, config.change, arguments.out, &report, &compared));
  if (monitor != nullptr && compared) PATROLMAP_RETURN_IF_ERROR(monitor->Close(report, map));
  if (compared) {
    std::printf(
        "changes since %s: %d of %zu places, %d new, %d removed, %d moved objects, %zu geometry regions; "
        "%d events in %s/events.jsonl\n",
        report.prior_flight.c_str(), report.ChangedPlaces(), report.places.size(),
        report.ObjectsIn(change::ObjectState::kNew), report.ObjectsIn(change::ObjectState::kRemoved),
        report.ObjectsIn(change::ObjectState::kMoved), report.geometry.regions.size(),
        monitor != nullptr ? monitor->events() : 0, arguments.out.c_str());
  }
  return pipeline::SaveMapRun(&map, arguments.out);
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
  if (!arguments.options.IsValid(&error) || !arguments.events.IsValid(&error)) return Status::InvalidArgument(error);
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
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(arguments.out));
  std::unique_ptr<pipeline::ChangeMonitor> monitor;
  PATROLMAP_RETURN_IF_ERROR(OpenMonitor(arguments, prior, config, &monitor));
  place::PlaceRecognizer recognizer(&vocabulary, config.place);
  PATROLMAP_RETURN_IF_ERROR(pipeline::SeedRecognizer(prior, arguments.prior_map, vocabulary, &recognizer));
  pipeline::DriveOptions drive;
  drive.paced = !arguments.fast && source->info().kind != "camera";
  drive.max_seconds = arguments.max_seconds;
  drive.stop = &stop_requested;
  drive.report = [](const pipeline::FlightPassStats& stats, double flight_s) {
    spdlog::info("{:.0f} s of flight, {} frames, {} key frames", flight_s, stats.frames, stats.key_frames);
  };
  pipeline::MapResult result;
  pipeline::FlightRun run;
  PATROLMAP_RETURN_IF_ERROR(
      pipeline::RunFlight(source.get(), config, arguments.options, drive, &recognizer, &result, monitor.get(), &run));
  if (run.drive.interrupted) spdlog::info("stop requested: writing the map");
  for (const std::string& warning : run.warnings) spdlog::warn("{}", warning);
  PATROLMAP_RETURN_IF_ERROR(WriteOutputs(arguments, config, prior, result, recognizer,
                                         pipeline::TagOf(vocabulary, vocabulary_path), &run, monitor.get()));
  PrintSummary(arguments, run, result);
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
  app.add_option("-o,--out", arguments.out,
                 "output folder: map.pmap, nodes.csv, loop_closures.csv, key_locations.csv; with --map events.jsonl, "
                 "changes.json, changes.html")
      ->capture_default_str();
  app.add_option("-c,--config", arguments.config, "YAML configuration (see config/default.yaml)");
  app.add_option("--vocabulary", arguments.vocabulary, "vocabulary file (default: the shipped one)");
  app.add_option("--fps", arguments.fps, "frame rate of a log without timestamps [Hz] (default: its own times)")
      ->check(patrolmap::tools::FiniteRange(0.001, 10000.0));
  app.add_flag("--fast", arguments.fast, "replay a log as fast as it can be processed, not at its own rate");
  app.add_option("--max-seconds", arguments.max_seconds, "stop after this much of the flight [s]; 0: at its end")
      ->check(patrolmap::tools::FiniteRange(0.0));
  app.add_flag(
      "--inline", [&arguments](std::int64_t) { arguments.options.workers = false; },
      "run place recognition and the change stage on the frame thread (the map and report are the same)");
  app.add_option("--queue", arguments.options.queue_capacity,
                 "inputs waiting for place recognition, and for the change stage, at most")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--ring-s", arguments.options.ring_s,
                 "seconds of processed frames kept for key locations confirmed late")
      ->capture_default_str()
      ->check(patrolmap::tools::FiniteRange(0.1, 3600.0));
  app.add_option("--events-interval-s", arguments.events.interval_s,
                 "with --map: flight time between checks of the object map and the grid for events [s]")
      ->capture_default_str()
      ->check(patrolmap::tools::FiniteRange(0.1, 3600.0));
  app.add_option("--events-settle-s", arguments.events.settle_s,
                 "with --map: the last views an object check leaves out (their detections may still come) [s]")
      ->capture_default_str()
      ->check(patrolmap::tools::FiniteRange(0.0, 3600.0));
  app.add_flag("-q,--quiet", quiet, "only print errors");
  app.footer(
      "With --map, the flight is compared with the map's last flight as it goes: each change found is appended to "
      "OUT/events.jsonl as one JSON line, and OUT/changes.json and OUT/changes.html are written at the end, as "
      "patrolmap patrol writes them. SIGINT or SIGTERM ends the stream; the map and the report are written as if "
      "it had ended, and the exit code is 0.");
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
