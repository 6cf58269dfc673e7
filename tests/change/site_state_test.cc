#include "patrolmap/change/site_state.h"

#include <vector>

#include <gtest/gtest.h>

#include "change/fixtures.h"
#include "patrolmap/change/change_detector.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::Depth;
using testing_fixtures::GridOf;
using testing_fixtures::kAtOrigin;
using testing_fixtures::Patrol;

// The camera at the origin turned round: it sees what lies behind the origin's view.
CameraPoseSample TurnedRound() {
  return {0, Eigen::Vector3d::Zero(), Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()))};
}

// Patrol a saw a box ahead; the map's last patrol b looked the other way. A patrol c that sees no box ahead is
// compared there with a, the latest patrol that observed it, and finds the box gone; with b alone it finds nothing.
TEST(LatestState, ARegionOnlyAnOlderPatrolSawIsComparedWithIt) {
  ChangeOptions options;
  graph::TopoMap map;
  map.SetPatrol(Patrol("a", GridOf(Depth(5.0f, true), options), false));
  map.SetPatrol(Patrol("b", GridOf(Depth(5.0f, false), options, TurnedRound()), false, TurnedRound()));
  std::vector<GridSource> sources;
  const PatrolRecord state = LatestState(map, *map.Patrol("b"), &sources);
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources[0].flight, "b");
  EXPECT_EQ(sources[0].voxels, static_cast<long long>(map.Patrol("b")->grid.voxels.size()));
  EXPECT_EQ(sources[1].flight, "a");
  EXPECT_GT(sources[1].voxels, 0);
  EXPECT_EQ(state.grid.voxels.size(), static_cast<std::size_t>(sources[0].voxels + sources[1].voxels));
  EXPECT_TRUE(std::is_sorted(state.grid.voxels.begin(), state.grid.voxels.end(), VoxelBefore));
  EXPECT_EQ(state.flight, "b");

  const PatrolRecord current = Patrol("c", GridOf(Depth(5.0f, false), options), false);
  ChangeReport with_state, with_b;
  ChangeDetector(state, options).Compare(current, {}, &with_state);
  ChangeDetector(*map.Patrol("b"), options).Compare(current, {}, &with_b);
  EXPECT_FALSE(with_state.geometry.regions.empty());
  EXPECT_TRUE(with_b.geometry.regions.empty());
}

// Where both saw a voxel, the later patrol's evidence stands; a grid of another voxel size is left out.
TEST(LatestState, TheLaterPatrolsEvidenceStands) {
  graph::TopoMap map;
  PatrolRecord a, b, other;
  a.flight = "a", b.flight = "b", other.flight = "other";
  a.grid.voxel_size = b.grid.voxel_size = 0.2;
  other.grid.voxel_size = 0.5;
  a.grid.voxels = {{0, 0, 0, 9, 0}, {1, 0, 0, 9, 0}};
  other.grid.voxels = {{5, 5, 5, 1, 1}};
  b.grid.voxels = {{1, 0, 0, 0, 7}};
  map.SetPatrol(a);
  map.SetPatrol(other);
  map.SetPatrol(b);
  std::vector<GridSource> sources;
  const PatrolRecord state = LatestState(map, *map.Patrol("b"), &sources);
  ASSERT_EQ(state.grid.voxels.size(), 2u);
  EXPECT_EQ(state.grid.voxels[0].hits, 9);    // only a saw (0, 0, 0)
  EXPECT_EQ(state.grid.voxels[1].passes, 7);  // b's (1, 0, 0)
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources[1].voxels, 1);
}

}  // namespace
}  // namespace patrolmap::change
