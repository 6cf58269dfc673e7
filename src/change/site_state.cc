#include "patrolmap/change/site_state.h"

#include <algorithm>
#include <iterator>

namespace patrolmap::change {

PatrolRecord LatestState(const graph::TopoMap& map, const PatrolRecord& prior, std::vector<GridSource>* sources) {
  PatrolRecord state = prior;
  sources->clear();
  const auto flown = [&map](const std::string& flight) {
    const auto span = map.FlightSpan(flight);
    return span ? span->first : TimestampNs{0};
  };
  if (!prior.grid.voxels.empty()) {
    sources->push_back({prior.flight, static_cast<long long>(prior.grid.voxels.size()), flown(prior.flight)});
  }
  const std::vector<std::string> flights = map.Flights();
  const auto at = std::find(flights.begin(), flights.end(), prior.flight);
  std::vector<VoxelEvidence> merged;
  for (auto flight = std::make_reverse_iterator(at); flight != flights.rend(); ++flight) {
    const PatrolRecord* earlier = map.Patrol(*flight);
    if (earlier == nullptr || earlier->grid.voxels.empty() || earlier->grid.voxel_size != prior.grid.voxel_size) {
      continue;
    }
    // std::set_union takes an equal voxel from its first range: the later patrol's observation stays.
    merged.clear();
    std::set_union(state.grid.voxels.begin(), state.grid.voxels.end(), earlier->grid.voxels.begin(),
                   earlier->grid.voxels.end(), std::back_inserter(merged), VoxelBefore);
    const auto added = static_cast<long long>(merged.size() - state.grid.voxels.size());
    if (added > 0) sources->push_back({earlier->flight, added, flown(earlier->flight)});
    state.grid.voxels.swap(merged);
  }
  return state;
}

}  // namespace patrolmap::change
