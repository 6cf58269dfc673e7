// The latest state of the site: what a new patrol is compared with. The map's last patrol may not have covered
// every region an earlier one saw; an archived patrol keeps exactly the voxels no later patrol observed
// (graph::MapRetention), so its grid, merged under the later ones, completes the picture.
#pragma once

#include <string>
#include <vector>

#include "patrolmap/change/report.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

// `prior`'s record (a patrol of `map`) with its evidence grid completed, voxel by voxel, by the most recent patrol
// flown before it that observed a voxel it did not (grids of the same voxel size only). `sources` receives, newest
// first, each patrol that gave voxels, how many and when it was flown.
PatrolRecord LatestState(const graph::TopoMap& map, const PatrolRecord& prior, std::vector<GridSource>* sources);

}  // namespace patrolmap::change
