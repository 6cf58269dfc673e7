// patrolmap map LOG [LOG ...] --out DIR [--config FILE] [--vocabulary FILE] [--every-frame]
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/words.h"
#include "patrolmap/pipeline/mapping.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct MapArguments {
  pipeline::MappingRequest request;
  bool every_frame = false;
  const char* command = "map";  // names its progress line
};

void PrintSummary(const pipeline::MappingOutcome& outcome, const std::string& out) {
  const pipeline::MapResult& result = outcome.places;
  const double nodes = std::max<std::size_t>(1, result.nodes.size());
  std::printf(
      "%s: %s, %s; per key frame %.1f ms features, %.2f ms query, %.1f ms "
      "verification, %.2f ms database update; outputs in %s\n",
      Counted(static_cast<long long>(outcome.flights.size()), "log", "logs").c_str(),
      Counted(static_cast<long long>(result.nodes.size()), "node", "nodes").c_str(),
      Counted(static_cast<long long>(result.loop_closures.size()), "loop closure", "loop closures").c_str(),
      1e3 * result.seconds_features / nodes, 1e3 * result.seconds_query / nodes, 1e3 * result.seconds_verify / nodes,
      1e3 * result.seconds_add / nodes, out.c_str());
}

int RunMap(MapArguments arguments) {
  pipeline::MappingRequest& request = arguments.request;
  request.pass.node_every = arguments.every_frame ? 1 : 0;
  request.pass.keep_samples = !arguments.every_frame;
  request.outputs = arguments.every_frame ? pipeline::FlightOutputs::kNone : pipeline::FlightOutputs::kDetection;
  Progress progress(arguments.command);
  request.drive.progress = [&progress](std::int64_t done, std::int64_t total) { progress.Update(done, total); };
  pipeline::MappingOutcome outcome;
  const Status status = pipeline::RunMapping(request, &outcome);
  if (!status.ok()) return Fail(status);
  if (outcome.compared) PrintChangeSummary(outcome.report, request.out);
  PrintSummary(outcome, request.out);
  return 0;
}

}  // namespace

Command AddPatrolCommand(CLI::App* app) {
  auto arguments = std::make_shared<MapArguments>();
  arguments->request.out = "patrolmap_patrol";
  arguments->command = "patrol";
  app->add_option("log", arguments->request.sources, "the new flight's log")->required()->expected(1);
  app->add_option("--map", arguments->request.prior_map, "the map of earlier flights (map.pmap)")
      ->required()
      ->check([](const std::string& path) { return path.empty() ? std::string("an empty map name") : std::string(); });
  app->add_option("-o,--out", arguments->request.out, "output folder")->capture_default_str();
  app->add_option("-c,--config", arguments->request.config_path, "YAML configuration (see config/default.yaml)");
  AddSetOption(app, &arguments->request.config_settings);
  app->add_option("--flight-id", arguments->request.flight_id,
                  "the new flight's id (default: meta.yaml's flight_id, else the log's folder or file name, made "
                  "unique in the map)");
  app->add_option("--vocabulary", arguments->request.vocabulary_path, "vocabulary file (default: the shipped one)");
  AddFpsOption(app, &arguments->request.fps);
  AddTopicOption(app, &arguments->request.topics);
  AddPosesOption(app, &arguments->request.poses);
  AddCameraOption(app, &arguments->request.camera);
  app->footer(
      "Closes loops of the new flight against every earlier flight of the map and writes the extended map to "
      "OUT/map.pmap, the new nodes and loop closures to OUT/nodes.csv and OUT/loop_closures.csv, and what changed "
      "since the map's last flight to OUT/changes.json and OUT/changes.html (as patrolmap diff).");
  return [arguments] { return RunMap(*arguments); };
}

Command AddMapCommand(CLI::App* app) {
  auto arguments = std::make_shared<MapArguments>();
  arguments->request.out = "patrolmap_map";
  app->add_option("logs", arguments->request.sources,
                  "flight log(s) as for detect; several are matched in order through one "
                  "database, so later flights close loops against earlier ones")
      ->required();
  app->add_option("-o,--out", arguments->request.out, "output folder")->capture_default_str();
  app->add_option("-c,--config", arguments->request.config_path, "YAML configuration (see config/default.yaml)");
  AddSetOption(app, &arguments->request.config_settings);
  app->add_option("--flight-id", arguments->request.flight_id,
                  "the new flight's id (default: meta.yaml's flight_id, else the log's folder or file name, made "
                  "unique in the map)");
  app->add_option("--vocabulary", arguments->request.vocabulary_path,
                  "vocabulary file (patrolmap vocab build; default: the shipped one, found beside the program, in "
                  "the install prefix or at $PATROLMAP_VOCABULARY)");
  AddFpsOption(app, &arguments->request.fps);
  AddTopicOption(app, &arguments->request.topics);
  AddPosesOption(app, &arguments->request.poses);
  AddCameraOption(app, &arguments->request.camera);
  app->add_flag("--every-frame", arguments->every_frame,
                "make every image a node, without key-location detection (image collections, place recognition "
                "alone); without timestamps 'recent' is counted in images (place.exclude_recent_images)");
  app->footer(
      "Writes OUT/map.pmap, OUT/nodes.csv and OUT/loop_closures.csv, and the detect outputs unless --every-frame.");
  return [arguments] { return RunMap(*arguments); };
}

}  // namespace patrolmap::tools
