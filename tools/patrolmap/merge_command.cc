// patrolmap merge A.pmap B.pmap ... --out DIR [--config FILE] [--vocabulary FILE] [--rename-clashes]
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/words.h"
#include "patrolmap/pipeline/merge.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

int RunMerge(pipeline::MergeRequest request) {
  Progress progress("merge", "nodes");
  request.progress = [&progress](std::int64_t done, std::int64_t total) { progress.Update(done, total); };
  pipeline::MergeOutcome outcome;
  const Status status = pipeline::RunMerge(request, &outcome);
  if (!status.ok()) return Fail(status);
  for (const auto& [old_id, new_id] : outcome.renamed)
    std::printf("renamed %s to %s\n", old_id.c_str(), new_id.c_str());
  const double nodes = std::max(1, outcome.nodes);
  std::printf("%s merged: %s, %s, %s (%d across maps); per node %.2f ms query, %.1f ms verification; outputs in %s\n",
              Counted(static_cast<long long>(request.maps.size()), "map", "maps").c_str(),
              Counted(outcome.flights, "flight", "flights").c_str(), Counted(outcome.nodes, "node", "nodes").c_str(),
              Counted(outcome.loop_closures, "loop closure", "loop closures").c_str(), outcome.across_maps,
              1e3 * outcome.seconds_query / nodes, 1e3 * outcome.seconds_verify / nodes, request.out.c_str());
  return 0;
}

}  // namespace

Command AddMergeCommand(CLI::App* app) {
  auto request = std::make_shared<pipeline::MergeRequest>();
  request->out = "patrolmap_merged";
  app->add_option("maps", request->maps, "map files (map.pmap) built with the same vocabulary")->required();
  app->add_option("-o,--out", request->out, "output folder")->capture_default_str();
  app->add_option("-c,--config", request->config_path,
                  "YAML configuration: the place.* keys the maps were built with (see config/default.yaml)");
  AddSetOption(app, &request->config_settings);
  app->add_option("--vocabulary", request->vocabulary_path,
                  "vocabulary file the maps were built with (default: the shipped one)");
  app->add_flag("--rename-clashes", request->rename_clashes,
                "a flight id found in several maps is renamed ID-2, ID-3, ... in the later maps (default: an error)");
  app->footer(
      "Orders the flights by their start (the first frame kept along the route, else the first node), then by id, and "
      "recognises every node again from its "
      "stored features against all nodes before it: the result is the map one 'patrolmap map' over all the logs "
      "in that order builds, whatever order or grouping the maps are merged in. Each flight keeps its patrol "
      "record, so 'patrolmap diff' works between any two flights. Writes OUT/map.pmap (last, atomically), "
      "OUT/nodes.csv and OUT/loop_closures.csv.");
  return [request] { return RunMerge(*request); };
}

}  // namespace patrolmap::tools
