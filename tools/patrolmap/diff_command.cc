// patrolmap diff MAP.pmap [--from FLIGHT] [--to FLIGHT] --out DIR [--config FILE]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/pipeline/change.h"

namespace patrolmap::tools {
namespace {

struct DiffArguments {
  std::string map;
  std::string from, to;  // default: the map's last two flights
  std::string out = "patrolmap_diff";
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
};

int RunDiff(const DiffArguments& arguments) {
  pipeline::Config config;
  graph::TopoMap map;
  Status status = LoadCheckedConfig(arguments.config, arguments.settings, &config);
  if (status.ok()) status = graph::LoadMap(arguments.map, &map);
  if (!status.ok()) return Fail(status);
  const std::vector<std::string> flights = map.Flights();
  std::string from = arguments.from, to = arguments.to;
  if (to.empty() && !flights.empty()) to = flights.back();
  if (from.empty() && flights.size() >= 2) from = flights[flights.size() - 2];
  if (from.empty() || to.empty())
    return Fail(Status::InvalidArgument(arguments.map + ": needs two flights to compare"));
  if (from == to) return Fail(Status::InvalidArgument("--from and --to name the same flight '" + from + "'"));
  change::ChangeReport report;
  status = pipeline::CompareFlights(map, from, to, pipeline::ChangeOptionsOf(config), &report);
  if (!status.ok()) return Fail(Status::InvalidArgument(arguments.map + ": " + status.message()));
  pipeline::AddSiteHistories(map, config.change.objects, &report);
  status = change::WriteChangeReport(report, map, arguments.out);
  if (!status.ok()) return Fail(status);
  PrintChangeSummary(report, arguments.out);
  return 0;
}

}  // namespace

void AddFpsOption(CLI::App* app, double* fps) {
  app->add_option("--fps", *fps,
                  "frame rate of an image folder, pattern or video [Hz] (default: from its times: times.txt, "
                  "numeric file names, the video's rate; else 30 with a warning)")
      ->check(FiniteRange(0.001, 10000.0));
}

void AddTopicOption(CLI::App* app, std::vector<std::string>* topics) {
  app->add_option(
         "--topic", *topics,
         "a ROS bag's topic for a role, as ROLE=TOPIC (roles: camera, camera_info, imu, gps, pose, depth, right); "
         "repeat for several; default: the first topic of each role's message type (patrolmap info BAG "
         "lists them)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void AddPosesOption(CLI::App* app, std::string* poses) {
  app->add_option("--poses", *poses,
                  "camera poses of the log from a file: TUM (t tx ty tz qx qy qz qw per line) or KITTI (a 3x4 "
                  "matrix per image); replaces the log's state estimate")
      ->check(CLI::ExistingFile);
}

void AddCameraOption(CLI::App* app, std::string* camera) {
  app->add_option("--camera", *camera,
                  "the camera's calibration, as a EuRoC sensor.yaml (intrinsics, resolution, optional "
                  "radial-tangential distortion), for image folders and patterns; replaces a EuRoC log's own")
      ->check(CLI::ExistingFile);
}

void PrintChangeSummary(const change::ChangeReport& report, const std::string& out) {
  std::printf("changes %s -> %s: %zu places compared, %d with appearance changes", report.prior_flight.c_str(),
              report.current_flight.c_str(), report.places.size(), report.ChangedPlaces());
  if (report.route.compared) {
    std::printf("; route: %zu of %d frames compared (%d with depth), %zu appearance changes", report.route.pairs.size(),
                report.route.current_frames, report.route.current_depth_frames, report.route.changes.size());
  }
  if (report.objects_compared) {
    std::printf("; objects: %d new, %d removed, %d moved, %d persistent, %d unobserved",
                report.ObjectsIn(change::ObjectState::kNew), report.ObjectsIn(change::ObjectState::kRemoved),
                report.ObjectsIn(change::ObjectState::kMoved), report.ObjectsIn(change::ObjectState::kPersistent),
                report.ObjectsIn(change::ObjectState::kUnobserved));
  }
  if (report.geometry_compared) {
    std::printf("; geometry: %zu regions, %zu changed voxels", report.geometry.regions.size(),
                report.geometry.changed_voxels.size());
  }
  std::printf("; report in %s/changes.json and changes.html\n", out.c_str());
}

Command AddDiffCommand(CLI::App* app) {
  auto arguments = std::make_shared<DiffArguments>();
  app->add_option("map", arguments->map, "map file (map.pmap) holding both flights")->required();
  app->add_option("--from", arguments->from, "the earlier flight (default: the map's second-to-last flight)");
  app->add_option("--to", arguments->to, "the later flight (default: the map's last flight)");
  app->add_option("-o,--out", arguments->out, "output folder")->capture_default_str();
  app->add_option("-c,--config", arguments->config, "YAML configuration (change.* keys; see config/default.yaml)");
  AddSetOption(app, &arguments->settings);
  app->footer(
      "Compares the two flights: appearance at every place both saw (their loop closures), objects when both "
      "logs had detections, geometry when both had depth. Writes OUT/changes.json (format "
      "patrolmap.changes, version 2: docs/changes.schema.json), OUT/changes.html, and with GPS OUT/changes.geojson and "
      "OUT/changes.kml.");
  return [arguments] { return RunDiff(*arguments); };
}

}  // namespace patrolmap::tools
