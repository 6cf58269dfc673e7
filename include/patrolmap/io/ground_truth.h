// Readers for the ground truth that simulated logs carry in <log>/groundtruth/.
#pragma once

#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

// One line of groundtruth/key_locations.csv: a building edge crossing the view axis.
struct TruthKeyLocationRecord {
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  bool opening = false;
};

// Reads <log>/groundtruth/key_locations.csv. NotFound when the log has none.
Status ReadTruthKeyLocations(const std::string& log, std::vector<TruthKeyLocationRecord>* truth);

}  // namespace patrolmap::io
