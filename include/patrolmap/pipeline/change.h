// Change detection for a patrol (DESIGN.md: prior map -> ChangeDetector ->
// change report): what a log's poses, detections and depth give its patrol
// record, and the comparison of two flights of a map.
#pragma once

#include <functional>
#include <string>

#include "patrolmap/change/report.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/pipeline/config.h"

namespace patrolmap::pipeline {

struct PatrolRecordStats {
  int detections = 0, associations = 0, skipped_detections = 0;
  double association_seconds = 0.0;
  int depth_frames = 0;
  int skipped_depth_frames = 0;  // unreadable or of the wrong size: reported and left out
  double grid_seconds = 0.0;
  long long dropped_voxel_updates = 0;
};

using ChangeProgress = std::function<void(std::int64_t, std::int64_t)>;

// The patrol record of `log`: its camera, views sampled along the state
// estimate, the object map (when it has objects0/) and the evidence grid
// (when it has depth0/). Without poses only the camera is filled. An
// unreadable depth image is reported on stderr, counted and left out. The
// caller sets feature_image_width (the mapping run knows it).
Status BuildPatrolRecord(const std::string& log, const Config& config, PatrolRecord* record,
                         PatrolRecordStats* stats = nullptr, const ChangeProgress& progress = {});

// Compares flight `prior` with flight `current` of `map`: appearance at every
// loop closure between their nodes, objects and geometry where both patrol
// records have them. Fails naming a flight that is not in the map.
Status CompareFlights(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                      const change::ChangeOptions& options, change::ChangeReport* report);

}  // namespace patrolmap::pipeline
