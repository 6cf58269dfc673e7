// Scoring loop closures against simulator ground truth (the paper's Table III:
// possible, found and false loop closures).
//
// Two nodes show the same place when their camera positions lie within
// radius_m and their camera headings within max_heading_deg of each other
// (groundtruth/places.csv of each flight). A query node has a possible loop
// closure when some node before it shows the same place: any node of an
// earlier flight, or a node of its own flight at least min_gap_s earlier (so
// that the neighbours along the path do not count). A reported closure is true
// when its two nodes show the same place, false otherwise; a node with a
// possible closure is found when at least one true closure has it as query.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::eval {

// Camera position [m] and heading of the optical axis [rad] at a frame.
struct Place {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

// A node of a run (nodes.csv): which flight and frame it comes from.
struct NodeRecord {
  int node = 0;
  std::string flight;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
};

// A reported loop closure (loop_closures.csv).
struct LoopClosureRecord {
  int query_node = 0;
  int matched_node = 0;
};

struct LoopClosureScoreOptions {
  double radius_m = 5.0;          // same place: camera positions at most this far apart [m]
  double max_heading_deg = 30.0;  // and camera headings at most this different [deg]
  double min_gap_s = 15.0;        // nodes of one flight closer in time are neighbours, not loop closures [s]
};

struct LoopClosureScore {
  int nodes = 0;
  int possible = 0;  // query nodes with a possible loop closure
  int found = 0;     // of those, with at least one true reported closure
  int reported = 0;  // reported closures
  int true_positives = 0;
  int false_positives = 0;
  std::vector<bool> correct;  // per reported closure
  // For each possible but not found query node: (its index in `nodes`, the earliest node of its place).
  std::vector<std::pair<int, int>> missed;
  double precision() const { return reported > 0 ? static_cast<double>(true_positives) / reported : 1.0; }
  double recall() const { return possible > 0 ? static_cast<double>(found) / possible : 1.0; }
};

// `places` gives each node's place (same order as `nodes`); flights are
// ordered as they first appear in `nodes`.
LoopClosureScore ScoreLoopClosures(const std::vector<NodeRecord>& nodes, const std::vector<Place>& places,
                                   const std::vector<LoopClosureRecord>& closures,
                                   const LoopClosureScoreOptions& options = {});

// Reads <log>/groundtruth/places.csv into a frame-indexed table.
Status ReadPlaces(const std::string& log, std::vector<Place>* places_by_frame);

// Reads a run's nodes.csv (node,flight,timestamp_ns,frame_index).
Status ReadNodesCsv(const std::string& path, std::vector<NodeRecord>* nodes);

// Reads a run's loop_closures.csv (query_node,matched_node,...).
Status ReadLoopClosuresCsv(const std::string& path, std::vector<LoopClosureRecord>* closures);

}  // namespace patrolmap::eval
