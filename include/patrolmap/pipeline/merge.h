// Merging maps built apart (a fleet's logs mapped on many machines): `patrolmap merge`.
//
// The merged map is the map one `patrolmap map` over all their logs would build, with the logs in the merge
// order: by each flight's start (its first route frame, else its first node), then by flight id (natural order). Each
// node is recognised again from its stored features and BoW vector (PlaceRecognizer::AddDescribedKeyFrame) against
// every node before it in that order, so closures within a map and across maps come out as one mapping run finds them,
// and merging is associative: pairwise merges in any order give the same nodes and closures. No log is read.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "patrolmap/core/status.h"

namespace patrolmap::pipeline {

struct MergeRequest {
  std::vector<std::string> maps;  // map files (map.pmap), at least one
  std::string out;                // output folder: OUT/map.pmap, OUT/nodes.csv, OUT/loop_closures.csv
  std::string config_path;        // YAML configuration (place.* as the maps were built with; empty: defaults)
  std::vector<std::string> config_settings;  // --set KEY=VALUE over it (ApplySettings)
  std::string vocabulary_path;               // empty: the default one; every map must record this vocabulary
  bool rename_clashes = false;  // a flight id in several maps: false fails, true renames the later ones ID-2, ...
  std::function<void(std::int64_t done, std::int64_t total)> progress;  // nodes recognised (may be empty)
};

struct MergeOutcome {
  int flights = 0, nodes = 0, loop_closures = 0;
  int across_maps = 0;                                       // loop closures between nodes of different input maps
  std::vector<std::pair<std::string, std::string>> renamed;  // (map file: flight, new id)
  double seconds_query = 0.0, seconds_verify = 0.0;          // summed over nodes
};

// Merges `request.maps` into OUT/map.pmap (written last and atomically, so a failed merge leaves no map).
// Fails naming the file and the problem: a map that does not load, another vocabulary, a flight id in two maps
// (without rename_clashes), an output that would overwrite an input.
Status RunMerge(const MergeRequest& request, MergeOutcome* outcome);

}  // namespace patrolmap::pipeline
