#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "change/fixtures.h"
#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::kCamera;
using testing_fixtures::LookingAlongX;

// Paper 004's occupancy: a voxel is occupied when most rays that reached it ended there, and (against a
// single stray return) at least two did. Seen 1, 2 and 3 times.
TEST(EvidenceGrid, AVoxelIsOccupiedFromTwoHitsThatOutnumberThePasses) {
  VoxelEvidence voxel;
  EXPECT_FALSE(IsOccupied(nullptr));
  voxel.hits = 1;
  EXPECT_FALSE(IsOccupied(&voxel));  // one hit: a stray return
  voxel.hits = 2;
  EXPECT_TRUE(IsOccupied(&voxel));
  voxel.passes = 2;
  EXPECT_FALSE(IsOccupied(&voxel));  // as many rays passed as ended
  voxel.hits = 3;
  EXPECT_TRUE(IsOccupied(&voxel));
}

const VoxelEvidence* At(const EvidenceGridData& grid, int x, int y, int z) {
  return FindVoxel(grid, Eigen::Vector3i(x, y, z));
}

TEST(EvidenceGrid, RayPassesVoxelsBeforeItsEndAndHitsTheLast) {
  EvidenceGridOptions options;
  options.voxel_size_m = 0.2;
  EvidenceGrid grid(options);
  grid.TraceRay(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0), true);  // voxels 0..5 along x
  grid.TraceRay(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.62, 0.0, 0.0), false);
  const EvidenceGridData data = grid.ToData();
  ASSERT_EQ(data.voxels.size(), 6u);
  for (int x = 0; x < 5; ++x) EXPECT_EQ(At(data, x, 0, 0)->passes, x <= 3 ? 2 : 1) << x;
  EXPECT_EQ(At(data, 5, 0, 0)->hits, 1);
  EXPECT_EQ(At(data, 5, 0, 0)->passes, 0);
  EXPECT_EQ(At(data, 3, 0, 0)->hits, 0);  // the second ray ended without a return
  EXPECT_EQ(At(data, 0, 1, 0), nullptr);
  EXPECT_TRUE(
      std::is_sorted(data.voxels.begin(), data.voxels.end(), [](const VoxelEvidence& a, const VoxelEvidence& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
      }));
}

TEST(EvidenceGrid, DiagonalRayVisitsAConnectedChainOfVoxels) {
  EvidenceGrid grid(EvidenceGridOptions{});
  grid.TraceRay(Eigen::Vector3d(0.05, 0.03, 0.01), Eigen::Vector3d(2.13, 1.57, -0.91), true);
  const EvidenceGridData data = grid.ToData();
  // From voxel (0,0,0) to (11,8,-5): 11 + 8 + 5 steps, each into a face neighbour.
  EXPECT_EQ(data.voxels.size(), 25u);
  EXPECT_EQ(At(data, 11, 8, -5)->hits, 1);
}

TEST(EvidenceGrid, TheMemoryBudgetCountsSixteenByteSlotsHalfUsedAndACopy) {
  EvidenceGridOptions options;  // 256 MB: 8,388,608 slots of 16 bytes, twice that while copying
  EXPECT_EQ(EvidenceGrid::MaxVoxels(options), 4194304u);
  options.memory_mb = 1024.0 / (1024 * 1024);  // 1 kB: 32 slots
  EXPECT_EQ(EvidenceGrid::MaxVoxels(options), 16u);
}

TEST(EvidenceGrid, AFullGridDropsTheUpdatesOfTheImageThatFilledIt) {
  EvidenceGridOptions options;
  options.memory_mb = 256.0 / (1024 * 1024);  // 4 voxels
  EvidenceGrid grid(options);
  grid.TraceRay(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 0.0, 0.0), true);  // 11 voxels, one image
  EXPECT_EQ(grid.voxel_count(), 4u);
  EXPECT_EQ(grid.dropped_updates(), 7);
  EXPECT_EQ(grid.evicted_voxels(), 0);
}

// One ray a depth image: 1 m along the camera's axis, 6 voxels of 0.2 m.
void IntegrateOneRay(EvidenceGrid* grid, double y) {
  const CameraIntrinsics one_pixel{1.0, 1.0, 0.0, 0.0, 1, 1};
  grid->Integrate(cv::Mat(1, 1, CV_32FC1, cv::Scalar(1.0)), one_pixel, LookingAlongX(Eigen::Vector3d(0, y, 0)));
}

TEST(EvidenceGrid, AFullGridDropsTheLeastRecentlyObservedVoxels) {
  EvidenceGridOptions options;
  options.memory_mb = 1024.0 / (1024 * 1024);  // 16 voxels
  options.rays_per_row = 1;
  EvidenceGrid grid(options);
  IntegrateOneRay(&grid, 0.0);
  IntegrateOneRay(&grid, 1.0);
  EXPECT_EQ(grid.voxel_count(), 12u);
  IntegrateOneRay(&grid, 2.0);  // full after 4 of its 6 voxels: the first image's 6 go
  EXPECT_EQ(grid.evicted_voxels(), 6);
  EXPECT_EQ(grid.dropped_updates(), 0);
  const EvidenceGridData data = grid.ToData();
  EXPECT_EQ(data.voxels.size(), 12u);
  EXPECT_EQ(At(data, 5, 0, 0), nullptr);  // the first ray's hit
  EXPECT_EQ(At(data, 5, 5, 0)->hits, 1);  // the second's
  EXPECT_EQ(At(data, 5, 10, 0)->hits, 1);
  IntegrateOneRay(&grid, 1.0);  // seen again: the second image's voxels are now the newest
  IntegrateOneRay(&grid, 3.0);
  EXPECT_EQ(grid.evicted_voxels(), 12);
  EXPECT_NE(At(grid.ToData(), 5, 5, 0), nullptr);
  EXPECT_EQ(At(grid.ToData(), 5, 10, 0), nullptr);
}

// Depth of a flat wall at x = 10 seen by a camera at the origin looking along +x.
cv::Mat WallDepth(const CameraIntrinsics& camera, double distance) {
  cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(distance));
  return depth;
}

TEST(EvidenceGrid, DepthImageRaysEndOnTheWall) {
  EvidenceGridOptions options;
  options.rays_per_row = 16;
  EvidenceGrid grid(options);
  grid.Integrate(WallDepth(kCamera, 10.0), kCamera, LookingAlongX(Eigen::Vector3d(0, 0, 2)));
  const EvidenceGridData data = grid.ToData();
  int wall_hits = 0, other_hits = 0, behind = 0, halfway_passes = 0;
  for (const VoxelEvidence& v : data.voxels) {
    (v.x == 50 ? wall_hits : other_hits) += v.hits;
    behind += v.x > 50;
    if (v.x == 25) halfway_passes += v.passes;
  }
  EXPECT_EQ(wall_hits, 16 * 12);  // every sampled pixel (16 rays a row: every 4th of 64 x 48) ends in the wall
  EXPECT_EQ(other_hits, 0);
  EXPECT_EQ(behind, 0);
  EXPECT_GE(halfway_passes, 16 * 12);
}

TEST(EvidenceGrid, TakingTheDataEmptiesTheGrid) {
  EvidenceGrid grid(EvidenceGridOptions{});
  grid.TraceRay(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0), true);
  const EvidenceGridData copy = grid.ToData();
  const EvidenceGridData taken = grid.TakeData();
  ASSERT_EQ(taken.voxels.size(), copy.voxels.size());
  EXPECT_EQ(taken.voxels.back().hits, 1);
  EXPECT_TRUE(grid.ToData().voxels.empty());
  grid.TraceRay(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.3, 0.0, 0.0), true);  // still usable
  EXPECT_EQ(grid.ToData().voxels.size(), 2u);
}

TEST(EvidenceGrid, UncertainReturnsLeaveTheSpaceJustBeforeThemUnknown) {
  EvidenceGrid grid(EvidenceGridOptions{});
  // Voxels 0..10 along x; those entered in the last 0.55 m (8 at 1.5 m, 9 at 1.7 m) are neither free nor hit.
  grid.TraceRay(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(2.0, 0.0, 0.0), true, 0.55);
  const EvidenceGridData data = grid.ToData();
  for (int x = 0; x <= 7; ++x) EXPECT_EQ(At(data, x, 0, 0)->passes, 1) << x;
  EXPECT_EQ(At(data, 8, 0, 0), nullptr);
  EXPECT_EQ(At(data, 9, 0, 0), nullptr);
  EXPECT_EQ(At(data, 10, 0, 0)->hits, 1);
}

TEST(EvidenceGrid, StereoDepthCarvesLessAndHitsOnlyWhereItIsSure) {
  EvidenceGridOptions options;
  options.rays_per_row = 16;
  EvidenceGrid exact(options), near_stereo(options), far_stereo(options);
  const cv::Mat wall = WallDepth(kCamera, 10.0);
  const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0, 0, 2));
  exact.Integrate(wall, kCamera, pose);
  // Range error 0.2 m at 10 m: hits, and 0.4 m (2 voxels) before the wall not carved.
  near_stereo.Integrate(wall, kCamera, pose, 0.2 / 100.0);
  // Range error 1 m at 10 m, above change.grid.max_hit_sigma_m (0.5 m): free space up to 8 m and no hit.
  far_stereo.Integrate(wall, kCamera, pose, 1.0 / 100.0);
  // The same error, averaged over 16 depth frames (depth::DepthFusion): a quarter, and hits again.
  EvidenceGrid fused(options);
  fused.Integrate(wall, kCamera, pose, 1.0 / 100.0, cv::Mat(wall.size(), CV_32F, cv::Scalar(0.25)));
  const auto count = [](const EvidenceGridData& data, int from_x, int to_x, bool hits) {
    long long total = 0;
    for (const VoxelEvidence& v : data.voxels) {
      if (v.x >= from_x && v.x <= to_x) total += hits ? v.hits : v.passes;
    }
    return total;
  };
  const EvidenceGridData a = exact.ToData(), b = near_stereo.ToData(), c = far_stereo.ToData();
  EXPECT_EQ(count(a, 50, 50, true), 16 * 12);
  EXPECT_EQ(count(b, 50, 50, true), 16 * 12);
  EXPECT_EQ(count(c, 0, 1000, true), 0);
  EXPECT_EQ(count(fused.ToData(), 50, 50, true), 16 * 12);
  EXPECT_GT(count(a, 48, 49, false), 0);
  EXPECT_EQ(count(b, 49, 49, false), 0);
  EXPECT_GT(count(b, 45, 46, false), 0);
  EXPECT_EQ(count(c, 41, 49, false), 0);
  EXPECT_GT(count(c, 30, 39, false), 0);
}

// Voxel cells of a grid: index -> (hits, passes).
using Cells = std::vector<std::pair<Eigen::Vector3i, std::pair<int, int>>>;

EvidenceGridData GridOf(const Cells& cells) {
  EvidenceGridData grid;
  grid.voxel_size = 0.2;
  for (const auto& [v, counts] : cells) {
    grid.voxels.push_back(
        {v.x(), v.y(), v.z(), static_cast<std::uint16_t>(counts.first), static_cast<std::uint16_t>(counts.second)});
  }
  std::sort(grid.voxels.begin(), grid.voxels.end(), [](const VoxelEvidence& a, const VoxelEvidence& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  return grid;
}

// The regions DiffGrids finds between the grids of the cells `before` and `after` (GridOf).
std::vector<GeometryRegion> RegionsBetween(const Cells& before, const Cells& after,
                                           const GeometryDiffOptions& options) {
  GeometryChange change;
  EXPECT_TRUE(DiffGrids(GridOf(before), GridOf(after), options, &change));
  return change.regions;
}

// The scenes below are mostly the changes themselves, which the pose check would take for a pose error.
GeometryDiffOptions SceneOfChanges() {
  GeometryDiffOptions options;
  options.max_differing_share = 1.0;
  return options;
}

TEST(GeometryChange, AppearedCubeIsOneRegionAndUnobservedSpaceIsNoChange) {
  Cells before, after;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) {
      for (int z = 1; z < 4; ++z) {
        before.push_back({{x, y, z}, {0, 10}});  // free before
        after.push_back({{x, y, z}, {8, 1}});    // occupied after: a new box
      }
    }
  }
  for (int y = 0; y < 10; ++y) {  // a wall, occupied in both
    before.push_back({{20, y, 1}, {9, 0}});
    after.push_back({{20, y, 1}, {7, 1}});
  }
  before.push_back({{40, 0, 1}, {0, 2}});  // seen too rarely in one patrol: unobserved
  after.push_back({{40, 0, 1}, {5, 0}});
  after.push_back({{50, 0, 1}, {5, 0}});   // never seen before: unobserved
  before.push_back({{60, 0, 1}, {0, 9}});  // an outlier voxel, below the region size
  after.push_back({{60, 0, 1}, {9, 0}});
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), SceneOfChanges(), &change));
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].voxels, 48);
  EXPECT_EQ(change.regions[0].appeared, 48);
  EXPECT_EQ(change.regions[0].vanished, 0);
  EXPECT_NEAR(change.regions[0].centroid.x(), 0.3, 1e-9);
  EXPECT_NEAR(change.regions[0].centroid.z(), 0.4, 1e-9);
  EXPECT_EQ(change.changed_voxels.size(), 48u);
  EXPECT_EQ(change.compared_voxels, 48 + 10 + 1);
  // Compared: at the box, at the wall (x = 4 m), beside the outlier (12 m); not where either patrol saw too little
  // (8 m, 10 m), nor far from everything.
  EXPECT_TRUE(change.ComparedNear({0.3, 0.3, 0.4}));
  EXPECT_TRUE(change.ComparedNear({4.0, 1.0, 0.2}));
  EXPECT_TRUE(change.ComparedNear({12.5, 0.5, 0.2}));
  EXPECT_FALSE(change.ComparedNear({8.0, 0.0, 0.2}));
  EXPECT_FALSE(change.ComparedNear({10.0, 0.0, 0.2}));
  EXPECT_FALSE(change.ComparedNear({-30.0, 40.0, 0.2}));
}

// A facade's edge seen from another angle: its voxels vanish at some heights and appear at others, all in one vertical
// plane (along an axis, or diagonal). That is no change; a box whose voxels both vanish and appear is one, and so is a
// new board one voxel thick.
TEST(GeometryChange, AnEdgeSeenAVoxelOffIsNoRegionWhateverItsDirection) {
  Cells before, after;
  const auto shifted = [&](const Eigen::Vector3i& at, bool vanished) {
    before.push_back({at, vanished ? std::make_pair(9, 0) : std::make_pair(0, 9)});
    after.push_back({at, vanished ? std::make_pair(0, 9) : std::make_pair(9, 0)});
  };
  for (int i = 0; i < 4; ++i) {
    for (int z = 1; z <= 6; ++z) {
      shifted({10, i, z}, z <= 3);      // in the plane x = 10
      shifted({30 + i, i, z}, z <= 3);  // in a diagonal plane
    }
  }
  for (int x = 0; x < 3; ++x) {  // a box: its lower half gone, an upper half new (a crate swapped for a taller one)
    for (int y = 50; y < 53; ++y) {
      for (int z = 1; z <= 4; ++z) shifted({x, y, z}, z <= 2);
    }
  }
  for (int y = 0; y < 4; ++y) {  // a new board, one voxel thick: it only appeared
    for (int z = 1; z <= 3; ++z) shifted({70, y, z}, false);
  }
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), SceneOfChanges(), &change));
  ASSERT_EQ(change.regions.size(), 2u);
  EXPECT_EQ(change.regions[0].voxels, 36);
  EXPECT_EQ(change.regions[1].voxels, 12);
  GeometryDiffOptions off = SceneOfChanges();
  off.min_shift_thickness_voxels = 0.0;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), off, &change));
  EXPECT_EQ(change.regions.size(), 4u);
}

// Two boxes seen solid in the second patrol. The first patrol saw one as free by many rays (it is new) and the other by
// a handful only, where the other patrol has over a hundred returns: rays past an occluder, not free space.
TEST(GeometryChange, AFewRaysThroughASurfaceSeenSolidAreNoFreeSpace) {
  Cells before, after;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) {
      for (int z = 1; z < 4; ++z) {
        before.push_back({{x, y, z}, {0, 30}});  // new box
        after.push_back({{x, y, z}, {100, 2}});
        before.push_back({{x + 20, y, z}, {0, 4}});  // a few rays through
        after.push_back({{x + 20, y, z}, {140, 3}});
      }
    }
  }
  GeometryDiffOptions options = SceneOfChanges();
  options.min_free_ratio = 0.0;
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), options, &change));
  EXPECT_EQ(change.regions.size(), 2u);  // off: both
  options.min_free_ratio = 0.1;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), options, &change));
  ASSERT_EQ(change.regions.size(), 1u);  // 4 rays < 0.1 x 140 returns; 30 >= 0.1 x 100
  EXPECT_NEAR(change.regions[0].centroid.x(), 0.3, 1e-9);
  ASSERT_TRUE(DiffGrids(GridOf(after), GridOf(before), options, &change));  // the same, vanished
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].vanished, 48);
}

// A 1 x 1 m patch of ground seen a voxel higher in the second patrol (what correcting GPS poses to the nearest
// whole voxel leaves) and a new flat lid 1 m up: both change one layer of voxels, but only the patch lies on the
// ground around it. It is no region; the lid is (with drop_ground_sheets off, both are).
TEST(GeometryChange, TheGroundSeenAVoxelHigherIsNoRegionALidAboveItIs) {
  Cells before, after;
  for (int x = -10; x < 25; ++x) {
    for (int y = -10; y < 15; ++y) {
      const bool patch = x >= 0 && x < 5 && y >= 0 && y < 5, lid = x >= 12 && x < 17 && y >= 0 && y < 5;
      before.push_back({{x, y, 0}, {8, 0}});  // the ground
      if (!patch) after.push_back({{x, y, 0}, {8, 0}});
      for (int z = 1; z <= 8; ++z) {
        before.push_back({{x, y, z}, {0, 10}});  // air
        const bool occupied = (patch && z == 1) || (lid && z == 5);
        after.push_back({{x, y, z}, occupied ? std::make_pair(8, 0) : std::make_pair(0, 10)});
      }
    }
  }
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), SceneOfChanges(), &change));
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].appeared, 25);
  EXPECT_NEAR(change.regions[0].centroid.z(), 1.0, 1e-9);
  GeometryDiffOptions keep = SceneOfChanges();
  keep.drop_ground_sheets = false;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), keep, &change));
  EXPECT_EQ(change.regions.size(), 2u);
}

// A sheet may also lie under the ground around it: the floor of a 1 x 1 m pit, seen a voxel lower in the second
// patrol, with the ground around it a voxel above the floor in both. Its ground is searched up to one voxel above
// it, so it is no region either (with drop_ground_sheets off it is one).
TEST(GeometryChange, APitFloorSeenAVoxelLowerIsNoRegion) {
  Cells before, after;
  for (int x = -10; x < 15; ++x) {
    for (int y = -10; y < 15; ++y) {
      const bool pit = x >= 0 && x < 5 && y >= 0 && y < 5;
      if (pit) {
        before.push_back({{x, y, 0}, {8, 0}});  // the floor
        before.push_back({{x, y, 1}, {0, 10}});
        after.push_back({{x, y, -1}, {8, 0}});  // the floor a voxel lower
        after.push_back({{x, y, 0}, {0, 10}});
        after.push_back({{x, y, 1}, {0, 10}});
      } else {
        before.push_back({{x, y, 1}, {8, 0}});  // the ground
        after.push_back({{x, y, 1}, {8, 0}});
      }
      for (int z = 2; z <= 8; ++z) {
        before.push_back({{x, y, z}, {0, 10}});  // air
        after.push_back({{x, y, z}, {0, 10}});
      }
    }
  }
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), SceneOfChanges(), &change));
  EXPECT_TRUE(change.regions.empty());
  GeometryDiffOptions keep = SceneOfChanges();
  keep.drop_ground_sheets = false;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), keep, &change));
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].vanished, 25);
}

// Two 3 x 3 x 4 voxel things seen solid in the first patrol. In the second, the rays pass through the lower three
// layers of both; the top layer of the first (a barrel whose plain side stereo saw through) stays occupied in both,
// the second is gone from top to foot. A third, new in the second patrol, is capped only by its own new voxels. The
// barrel is no region unless the cap test is off, asks for more columns, or its cap stands beyond the search; and
// the test is off for a --poses file, whose frame may not have z up.
TEST(GeometryChange, AThingWhoseTopStillStandsWasSeenThroughNotRemoved) {
  Cells before, after;
  const std::pair<int, int> solid(8, 0), free(0, 10);
  for (const int x0 : {0, 20, 40}) {
    for (int x = x0; x < x0 + 3; ++x) {
      for (int y = 0; y < 3; ++y) {
        for (int z = 1; z <= 4; ++z) {
          before.push_back({{x, y, z}, x0 == 40 ? free : solid});
          after.push_back({{x, y, z}, (x0 == 0 && z == 4) || x0 == 40 ? solid : free});
        }
      }
    }
  }
  const std::vector<GeometryRegion> found = RegionsBetween(before, after, SceneOfChanges());
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].vanished + found[1].vanished, 36);  // the second thing
  EXPECT_EQ(found[0].appeared + found[1].appeared, 36);  // the new one
  GeometryDiffOptions off = SceneOfChanges(), more = SceneOfChanges();
  off.min_capped_columns = 0;
  more.min_capped_columns = 10;  // the barrel has 9 columns
  EXPECT_EQ(RegionsBetween(before, after, off).size(), 3u);
  EXPECT_EQ(RegionsBetween(before, after, more).size(), 3u);
  for (auto* grid : {&before, &after}) {  // the barrel's lower layers 3 voxels lower: its cap 4 above them
    for (auto& voxel : *grid) voxel.first.z() -= voxel.first.x() < 3 && voxel.first.z() < 4 ? 3 : 0;
  }
  EXPECT_EQ(RegionsBetween(before, after, SceneOfChanges()).size(), 3u);
  EXPECT_EQ(ForPoseSources(SceneOfChanges(), kPosesFromFile, kPosesFromStateEstimate).min_capped_columns, 0);
  EXPECT_EQ(ForPoseSources(SceneOfChanges(), kPosesFromGps, kPosesFromStateEstimate).min_capped_columns, 2);
}

TEST(GeometryChange, DistantClustersStaySeparateAndOverlappingRegionsMerge) {
  Cells before, after;
  const auto removed_box = [&](int x0, int length) {
    for (int x = x0; x < x0 + length; ++x) {
      for (int z = 1; z < 3; ++z) {
        before.push_back({{x, 0, z}, {6, 0}});
        after.push_back({{x, 0, z}, {0, 6}});
      }
    }
  };
  removed_box(0, 6);    // 12 voxels
  removed_box(50, 20);  // a 4 m long object: clustering by centroid distance splits it, the cleanup joins it
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), SceneOfChanges(), &change));
  ASSERT_EQ(change.regions.size(), 2u);
  EXPECT_EQ(change.regions[0].voxels, 40);
  EXPECT_EQ(change.regions[0].vanished, 40);
  EXPECT_EQ(change.regions[1].voxels, 12);
}

// A ground plane and a wall seen two voxels apart everywhere (the second patrol's poses are off): every surface
// differs, which no change does, so nothing is reported. With a box put down on a ground both patrols agree on,
// only the box differs and it is reported.
TEST(GeometryChange, SurfacesThatDifferEverywhereAreAPoseErrorNotAChange) {
  Cells before, after;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 40; ++y) {
      before.push_back({{x, y, 0}, {8, 0}});  // the ground, occupied, with free air above it
      before.push_back({{x, y, 2}, {0, 8}});
      after.push_back({{x, y, 0}, {0, 8}});  // ... seen two voxels higher
      after.push_back({{x, y, 2}, {8, 0}});
    }
  }
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), GeometryDiffOptions{}, &change));
  EXPECT_TRUE(change.poses_disagree);
  EXPECT_TRUE(change.regions.empty());
  EXPECT_TRUE(change.changed_voxels.empty());
  EXPECT_EQ(change.surface_voxels, 3200);
  EXPECT_EQ(change.differing_voxels, 3200);
  // The same ground in both, and a 4 x 4 x 2 box put down on it.
  after = before;
  for (auto& [index, counts] : after) {
    if (index.z() == 2 && index.x() >= 10 && index.x() < 14 && index.y() >= 10 && index.y() < 14) counts = {8, 0};
  }
  for (int x = 10; x < 14; ++x) {
    for (int y = 10; y < 14; ++y) {
      before.push_back({{x, y, 1}, {0, 8}});
      after.push_back({{x, y, 1}, {8, 0}});
    }
  }
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), GeometryDiffOptions{}, &change));
  EXPECT_FALSE(change.poses_disagree);
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].appeared, 32);
  EXPECT_EQ(change.differing_voxels, 32);
  GeometryDiffOptions strict;
  strict.max_differing_share = 0.01;  // 32 of the 1632 surface voxels differ
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), strict, &change));
  EXPECT_TRUE(change.poses_disagree);
}

// A voxel free in one patrol and half occupied in the other (8 hits of 15 rays: 0.53) has changed, though it stays
// under the surface voxels' occupancy (0.55); it counts as a surface voxel too, so the share of differing surface
// voxels never exceeds one (the warning said "differ in 110 %").
TEST(GeometryChange, TheDifferingShareCountsEveryChangedVoxelAsASurface) {
  Cells before, after;
  for (int x = 0; x < 10; ++x) {
    before.push_back({{x, 0, 1}, {0, 15}});
    after.push_back({{x, 0, 1}, {8, 7}});
  }
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), GeometryDiffOptions{}, &change));
  EXPECT_EQ(change.differing_voxels, 10);
  EXPECT_EQ(change.surface_voxels, 10);
  EXPECT_DOUBLE_EQ(change.DifferingShare(), 1.0);
}

TEST(GeometryChange, DifferentVoxelSizesCannotBeCompared) {
  EvidenceGridData a, b;
  a.voxel_size = 0.2, b.voxel_size = 0.25;
  GeometryChange change;
  EXPECT_FALSE(DiffGrids(a, b, GeometryDiffOptions{}, &change));
  EXPECT_FALSE(DiffGrids(EvidenceGridData{}, EvidenceGridData{}, GeometryDiffOptions{}, &change));
}

// The onboard checks compare the prior with the grid still being built, in place: the same change as with
// the grid's stored copy, voxel for voxel and region for region.
TEST(GeometryChange, TheLiveGridGivesTheChangeItsCopyGives) {
  EvidenceGridOptions options;
  EvidenceGrid before(options), after(options);
  const Eigen::Vector3d origin(0.0, 0.0, 1.0);
  for (int pass = 0; pass < 4; ++pass) {
    for (int y = -20; y <= 20; ++y) {
      for (int z = 0; z <= 20; ++z) {
        const Eigen::Vector3d wall(10.0, 0.1 * y, 0.1 * z);
        before.TraceRay(origin, wall, true);
        // A box 1 m wide and 1 m tall stands at x = 5 in the later patrol: the rays that reach it end there.
        const Eigen::Vector3d at_box = origin + 0.5 * (wall - origin);
        const bool boxed = std::abs(at_box.y()) <= 0.5 && at_box.z() <= 1.0;
        after.TraceRay(origin, boxed ? at_box : wall, true);
      }
    }
  }
  const EvidenceGridData prior = before.ToData();
  GeometryChange from_copy, in_place;
  ASSERT_TRUE(DiffGrids(prior, after.ToData(), GeometryDiffOptions{}, &from_copy));
  ASSERT_TRUE(DiffGrids(prior, after, GeometryDiffOptions{}, &in_place));
  ASSERT_GE(from_copy.regions.size(), 1u) << from_copy.compared_voxels << " compared";
  EXPECT_GT(from_copy.changed_voxels.size(), 10u);
  EXPECT_EQ(in_place.compared_voxels, from_copy.compared_voxels);
  EXPECT_EQ(in_place.changed_voxels, from_copy.changed_voxels);
  ASSERT_EQ(in_place.regions.size(), from_copy.regions.size());
  for (std::size_t i = 0; i < in_place.regions.size(); ++i) {
    EXPECT_EQ(in_place.regions[i].voxels, from_copy.regions[i].voxels);
    EXPECT_EQ(in_place.regions[i].appeared, from_copy.regions[i].appeared);
    EXPECT_EQ(in_place.regions[i].centroid, from_copy.regions[i].centroid);
    EXPECT_EQ(in_place.regions[i].score, from_copy.regions[i].score);
  }
  VoxelEvidence voxel;
  EXPECT_FALSE(after.Lookup(Eigen::Vector3i(500, 500, 500), &voxel));
}

}  // namespace
}  // namespace patrolmap::change
