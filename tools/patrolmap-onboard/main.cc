// patrolmap-onboard: maps live, from a camera or a log replayed at its real rate (DESIGN.md, front ends).
// pipeline::RunMapping does the work: the flow stage on the frame thread, place recognition and the change
// stage on workers behind bounded queues. SIGINT and SIGTERM stop the stream and the map is written
// (atomically) as if it had ended.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <string>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "../cli_checks.h"
#include "patrolmap/pipeline/mapping.h"

namespace patrolmap::onboard {
namespace {

std::atomic<bool> stop_requested{false};

void RequestStop(int) { stop_requested.store(true); }

struct Arguments {
  pipeline::MappingRequest request;
  bool fast = false;
  pipeline::ChangeEventOptions events;
};

void PrintSummary(const pipeline::MappingOutcome& outcome, const std::string& out) {
  const pipeline::FlightRun& run = outcome.flights.back();
  const pipeline::FlightPassStats& s = run.result.stats;
  const pipeline::DriveResult& pace = run.drive;
  if (outcome.compared) {
    const change::ChangeReport& report = outcome.report;
    std::printf(
        "changes since %s: %d of %zu places, %d new, %d removed, %d moved objects, %zu geometry regions; "
        "%d events in %s/events.jsonl\n",
        report.prior_flight.c_str(), report.ChangedPlaces(), report.places.size(),
        report.ObjectsIn(change::ObjectState::kNew), report.ObjectsIn(change::ObjectState::kRemoved),
        report.ObjectsIn(change::ObjectState::kMoved), report.geometry.regions.size(), outcome.events, out.c_str());
  }
  std::printf(
      "%s%lld frames in %.1f s (%.1f frames/s), %lld processed: flow %.2f ms per processed frame (slowest "
      "%.1f ms); %d key frames (%d lost from the ring), %zu nodes, %zu loop closures; place queue at most %d "
      "deep, change queue %d, frame thread waited %.2f s for them, fell at most %.3f s behind the log's clock; "
      "outputs in %s\n",
      pace.interrupted ? "interrupted: " : "", static_cast<long long>(s.frames), pace.seconds,
      pace.seconds > 0 ? s.frames / pace.seconds : 0.0, static_cast<long long>(s.processed),
      s.processed ? 1e3 * s.flow_seconds / s.processed : 0.0, 1e3 * s.max_flow_seconds, s.key_frames, s.lost_key_frames,
      outcome.places.nodes.size(), outcome.places.loop_closures.size(), s.place_queue.max_depth,
      s.change_queue.max_depth, s.place_queue.waited_seconds + s.change_queue.waited_seconds, pace.max_lag_seconds,
      out.c_str());
}

Status Run(Arguments arguments) {
  pipeline::MappingRequest& request = arguments.request;
  request.outputs = pipeline::FlightOutputs::kKeyLocations;
  if (!request.prior_map.empty()) request.events = arguments.events;
  request.drive.paced = !arguments.fast;
  request.drive.stop = &stop_requested;
  request.drive.report = [](const pipeline::FlightPassStats& stats, double flight_s) {
    spdlog::info("{:.0f} s of flight, {} frames, {} key frames", flight_s, stats.frames, stats.key_frames);
  };
  pipeline::MappingOutcome outcome;
  PATROLMAP_RETURN_IF_ERROR(pipeline::RunMapping(request, &outcome));
  PrintSummary(outcome, request.out);
  return Status::Ok();
}

}  // namespace
}  // namespace patrolmap::onboard

int main(int argc, char** argv) {
  using patrolmap::onboard::Arguments;
  Arguments arguments;
  arguments.request.out = "patrolmap_onboard";
  arguments.request.sources.resize(1);
  CLI::App app{"patrolmap-onboard: maps live from a camera or a flight log replayed at its real rate"};
  app.set_version_flag("--version", "patrolmap-onboard 0.1.0");
  bool quiet = false;
  app.add_option("source", arguments.request.sources[0], "a flight log (any form patrolmap map reads) or camera:N")
      ->required();
  app.add_option("--map", arguments.request.prior_map, "map of earlier flights to close loops against (map.pmap)");
  app.add_option("-o,--out", arguments.request.out,
                 "output folder: map.pmap, nodes.csv, loop_closures.csv, key_locations.csv; with --map events.jsonl, "
                 "changes.json, changes.html")
      ->capture_default_str();
  app.add_option("-c,--config", arguments.request.config_path, "YAML configuration (see config/default.yaml)");
  patrolmap::tools::AddSetOption(&app, &arguments.request.config_settings);
  app.add_option("--flight-id", arguments.request.flight_id,
                 "the flight's id (default: the log's own, or cameraN, made unique in the map)");
  app.add_option("--vocabulary", arguments.request.vocabulary_path, "vocabulary file (default: the shipped one)");
  app.add_option("--fps", arguments.request.fps, "frame rate of a log without timestamps [Hz] (default: its own times)")
      ->check(patrolmap::tools::FiniteRange(0.001, 10000.0));
  app.add_option("--poses", arguments.request.poses,
                 "camera poses of the log from a file: TUM (t tx ty tz qx qy qz qw per line) or KITTI (a 3x4 "
                 "matrix per image); replaces the log's state estimate")
      ->check(CLI::ExistingFile);
  app.add_option("--camera", arguments.request.camera,
                 "the camera's calibration, as a EuRoC sensor.yaml (intrinsics, resolution, optional "
                 "radial-tangential distortion), for image folders and patterns; replaces a EuRoC log's own")
      ->check(CLI::ExistingFile);
  app.add_option(
         "--topic", arguments.request.topics,
         "a ROS bag's topic for a role, as ROLE=TOPIC (camera, camera_info, imu, gps, pose, depth, right); repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_flag("--fast", arguments.fast, "replay a log as fast as it can be processed, not at its own rate");
  app.add_option("--max-seconds", arguments.request.drive.max_seconds,
                 "stop after this much of the flight [s]; 0: at its end")
      ->check(patrolmap::tools::FiniteRange(0.0));
  app.add_flag(
      "--inline", [&arguments](std::int64_t) { arguments.request.pass.workers = false; },
      "run place recognition and the change stage on the frame thread (the map and report are the same)");
  app.add_option("--queue", arguments.request.pass.queue_capacity,
                 "inputs waiting for place recognition, and for the change stage, at most")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--ring-s", arguments.request.pass.ring_s,
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
  app.add_option("--events-min-observations", arguments.events.min_observations,
                 "with --map: rays per voxel in each patrol for a check while flying to compare it (the report "
                 "after the flight uses change.geometry.min_observations)")
      ->capture_default_str()
      ->check(CLI::Range(1, 65535));
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
