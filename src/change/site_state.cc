#include "patrolmap/change/site_state.h"

#include <algorithm>
#include <iterator>

namespace patrolmap::change {

PatrolRecord LatestState(const graph::TopoMap& map, const PatrolRecord& prior, std::vector<GridSource>* sources) {
  sources->clear();
  const auto flown = [&map](const std::string& flight) {
    const auto span = map.FlightSpan(flight);
    return span ? span->first : TimestampNs{0};
  };
  if (!prior.grid.voxels.empty()) {
    sources->push_back({prior.flight, static_cast<long long>(prior.grid.voxels.size()), flown(prior.flight)});
  }
  const auto holds = [](const std::vector<VoxelEvidence>& voxels, const VoxelEvidence& v) {
    return std::binary_search(voxels.begin(), voxels.end(), v, VoxelBefore);
  };
  // The voxels prior did not observe, each from the latest earlier patrol that did (newest first).
  std::vector<VoxelEvidence> older, fresh, merged;
  const std::vector<std::string> flights = map.Flights();
  const auto at = std::find(flights.begin(), flights.end(), prior.flight);
  for (auto flight = std::make_reverse_iterator(at); flight != flights.rend(); ++flight) {
    const PatrolRecord* earlier = map.Patrol(*flight);
    if (earlier == nullptr || earlier->grid.voxel_size != prior.grid.voxel_size) continue;
    fresh.clear();
    for (const VoxelEvidence& v : earlier->grid.voxels) {
      if (!holds(prior.grid.voxels, v) && !holds(older, v)) fresh.push_back(v);
    }
    if (fresh.empty()) continue;
    sources->push_back({earlier->flight, static_cast<long long>(fresh.size()), flown(earlier->flight)});
    merged.clear();
    std::merge(older.begin(), older.end(), fresh.begin(), fresh.end(), std::back_inserter(merged), VoxelBefore);
    older.swap(merged);
  }
  PatrolRecord state = prior;
  if (older.empty()) return state;
  state.grid.voxels.clear();
  state.grid.voxels.shrink_to_fit();  // the copy goes before the merged grid is made
  state.grid.voxels.reserve(prior.grid.voxels.size() + older.size());
  std::merge(prior.grid.voxels.begin(), prior.grid.voxels.end(), older.begin(), older.end(),
             std::back_inserter(state.grid.voxels), VoxelBefore);
  return state;
}

}  // namespace patrolmap::change
