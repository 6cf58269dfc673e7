#include "patrolmap/change/grid_alignment.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "patrolmap/change/evidence_grid.h"

namespace patrolmap::change {
namespace {

// A ground plane, a wall along it and a box: occupied voxels with free air in front, in ascending order.
EvidenceGridData Scene(const Eigen::Vector3i& offset, bool with_box) {
  EvidenceGridData grid;
  grid.voxel_size = 0.2;
  const auto add = [&](int x, int y, int z, bool occupied) {
    grid.voxels.push_back({x + offset.x(), y + offset.y(), z + offset.z(), static_cast<std::uint16_t>(occupied ? 6 : 0),
                           static_cast<std::uint16_t>(occupied ? 0 : 6)});
  };
  for (int x = 0; x < 60; ++x) {
    for (int y = 0; y < 40; ++y) {
      for (int z = 0; z < 12; ++z) {
        const bool wall = y == 30 && x % 7 != 3;  // a wall with gaps (windows): a shift along it is seen too
        const bool box = with_box && x >= 10 && x < 15 && y >= 10 && y < 15 && z >= 1 && z < 5;
        add(x, y, z, z == 0 || wall || box);
      }
    }
  }
  std::sort(grid.voxels.begin(), grid.voxels.end(), VoxelBefore);
  return grid;
}

TEST(GridAlignment, AFlightShiftedByWholeVoxelsIsMovedBack) {
  const EvidenceGridData prior = Scene(Eigen::Vector3i::Zero(), false);
  const EvidenceGridData current = Scene(Eigen::Vector3i(4, -3, 1), true);  // 0.8, -0.6, 0.2 m off, a new box
  const GridShift shift = FindGridShift(prior, current, GridAlignmentOptions{});
  ASSERT_TRUE(shift.applied);
  EXPECT_EQ(shift.voxels, Eigen::Vector3i(-4, 3, -1));
  EXPECT_GT(shift.overlap, 2 * shift.overlap_unshifted);
  PatrolRecord record;
  record.grid = current;
  MapObject object;
  object.centroid = Eigen::Vector3d(1, 1, 1);
  object.points = {Eigen::Vector3f(1, 1, 1)};
  record.objects = {object};
  record.views = {CameraPoseSample{0, Eigen::Vector3d(5, 5, 2), Eigen::Quaterniond::Identity()}};
  ShiftRecord(shift.voxels, &record);
  EXPECT_TRUE(std::is_sorted(record.grid.voxels.begin(), record.grid.voxels.end(), VoxelBefore));
  EXPECT_EQ(record.grid.voxels.front().x, 0);
  EXPECT_TRUE(record.objects[0].centroid.isApprox(Eigen::Vector3d(0.2, 1.6, 0.8)));
  EXPECT_TRUE(record.objects[0].points[0].isApprox(Eigen::Vector3f(0.2f, 1.6f, 0.8f)));
  EXPECT_TRUE(record.views[0].position.isApprox(Eigen::Vector3d(4.2, 5.6, 1.8)));
}

// Flights whose poses agree keep them, however much changed; beyond max_shift_m nothing is searched.
TEST(GridAlignment, PosesThatAgreeAndShiftsOutOfReachAreLeftAlone) {
  const EvidenceGridData prior = Scene(Eigen::Vector3i::Zero(), false);
  const GridShift same = FindGridShift(prior, Scene(Eigen::Vector3i::Zero(), true), GridAlignmentOptions{});
  EXPECT_FALSE(same.applied);
  EXPECT_FALSE(same.Undecided());
  EXPECT_EQ(same.voxels, Eigen::Vector3i::Zero());
  GridAlignmentOptions near;
  near.max_shift_m = 0.4;  // two voxels
  EXPECT_FALSE(FindGridShift(prior, Scene(Eigen::Vector3i(5, 0, 0), false), near).applied);
  near.max_shift_m = 0.0;
  EXPECT_FALSE(FindGridShift(prior, Scene(Eigen::Vector3i(1, 0, 0), false), near).applied);
  EvidenceGridData other = prior;
  other.voxel_size = 0.25;
  EXPECT_FALSE(FindGridShift(prior, other, GridAlignmentOptions{}).applied);
}

// A ground (2400 voxels) the same in both, and a wall (480) two voxels further in the current grid: moving the
// wall back costs 120 ground voxels, so the shift overlaps 15 % more than none. Taken only with min_gain below that;
// with the default the alignment is undecided.
TEST(GridAlignment, AShiftThatGainsLessThanMinGainIsNotTaken) {
  const auto grid = [](int wall_y) {
    EvidenceGridData g;
    g.voxel_size = 0.2;
    for (int x = 0; x < 60; ++x) {
      for (int y = 0; y < 40; ++y) g.voxels.push_back({x, y, 0, 6, 0});
      for (int z = 1; z <= 8; ++z) g.voxels.push_back({x, wall_y, z, 6, 0});
    }
    std::sort(g.voxels.begin(), g.voxels.end(), VoxelBefore);
    return g;
  };
  const EvidenceGridData prior = grid(30), current = grid(32);
  GridShift shift = FindGridShift(prior, current, GridAlignmentOptions{});
  EXPECT_FALSE(shift.applied);
  EXPECT_EQ(shift.overlap, 2400);
  EXPECT_TRUE(shift.Undecided());  // the shift fits better, not by min_gain: the onboard checks wait
  EXPECT_EQ(shift.best, Eigen::Vector3i(0, -2, 0));
  EXPECT_EQ(shift.best_overlap, 2280 + 480);
  GridAlignmentOptions eager;
  eager.min_gain = 0.1;
  shift = FindGridShift(prior, current, eager);
  ASSERT_TRUE(shift.applied);
  EXPECT_EQ(shift.voxels, Eigen::Vector3i(0, -2, 0));
  EXPECT_EQ(shift.overlap, 2280 + 480);
}

// The onboard case: the current flight's grid is still being built and is read in place. Its shift is found as
// from a copy, and comparing through the shift finds the new box where the prior map has it, while without it
// the poses disagree.
TEST(GridAlignment, AGridStillBeingBuiltIsComparedThroughItsShift) {
  const EvidenceGridData prior = Scene(Eigen::Vector3i::Zero(), false);
  const Eigen::Vector3i offset(4, -3, 1);
  const EvidenceGridData copy = Scene(offset, true);
  EvidenceGridOptions options;
  options.voxel_size_m = copy.voxel_size;
  EvidenceGrid live(options);
  for (const VoxelEvidence& v : copy.voxels) {  // a ray that starts and ends in the voxel counts it once
    const Eigen::Vector3d centre = Eigen::Vector3d(v.x, v.y, v.z) * copy.voxel_size;
    for (int i = 0; i < 6; ++i) live.TraceRay(centre, centre, v.hits > 0);
  }
  const GridShift from_copy = FindGridShift(prior, copy, GridAlignmentOptions{});
  const GridShift in_place = FindGridShift(prior, live, GridAlignmentOptions{});
  ASSERT_TRUE(in_place.applied);
  EXPECT_EQ(in_place.voxels, -offset);
  EXPECT_EQ(in_place.overlap, from_copy.overlap);
  EXPECT_EQ(in_place.overlap_unshifted, from_copy.overlap_unshifted);

  GeometryDiffOptions diff;
  GeometryChange unshifted, shifted;
  ASSERT_TRUE(DiffGrids(prior, live, diff, &unshifted));
  EXPECT_TRUE(unshifted.poses_disagree);
  ASSERT_TRUE(DiffGrids(prior, live, diff, &shifted, in_place.voxels));
  EXPECT_FALSE(shifted.poses_disagree);
  ASSERT_EQ(shifted.regions.size(), 1u);
  // The box fills x 10-14, y 10-14, z 1-4 of the prior's frame (2.0-2.8 m, 2.0-2.8 m, 0.2-0.8 m).
  EXPECT_NEAR(shifted.regions[0].centroid.x(), 2.4, 0.05);
  EXPECT_NEAR(shifted.regions[0].centroid.y(), 2.4, 0.05);
  EXPECT_EQ(shifted.regions[0].appeared, shifted.regions[0].voxels);
  VoxelEvidence voxel;
  EXPECT_TRUE(LookupIn(live, in_place.voxels)(Eigen::Vector3i(12, 12, 2), &voxel));
  EXPECT_EQ(voxel.x, 12);
  EXPECT_EQ(voxel.hits, 6);
}

}  // namespace
}  // namespace patrolmap::change
