#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/geometry_objects.h"

namespace patrolmap::change {
namespace {

constexpr double kVoxel = 0.2;

// The surface voxels of a box of nx x ny x nz voxels whose lowest corner voxel is `corner`; with `l_shape` the
// top half of the box keeps only its first half along x (an object that is not symmetric).
std::vector<Eigen::Vector3i> BoxSurface(const Eigen::Vector3i& corner, int nx, int ny, int nz, bool l_shape = false) {
  std::vector<Eigen::Vector3i> voxels;
  for (int z = 0; z < nz; ++z) {
    const int width = l_shape && z >= nz / 2 ? nx / 2 : nx;
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < width; ++x) {
        const bool surface = x == 0 || y == 0 || z == 0 || x == width - 1 || y == ny - 1 || z == nz - 1;
        if (surface) voxels.push_back(corner + Eigen::Vector3i(x, y, z));
      }
    }
  }
  return voxels;
}

// The voxels turned by 90 degrees about the vertical through voxel `pivot`.
std::vector<Eigen::Vector3i> Turned(const std::vector<Eigen::Vector3i>& voxels, const Eigen::Vector3i& pivot) {
  std::vector<Eigen::Vector3i> turned;
  for (const Eigen::Vector3i& v : voxels) {
    const Eigen::Vector3i d = v - pivot;
    turned.push_back(pivot + Eigen::Vector3i(-d.y(), d.x(), d.z()));
  }
  return turned;
}

// A geometry change holding `appeared` (occupancy +0.9) and `vanished` (-0.9) voxels, sorted as DiffGrids sorts.
GeometryChange ChangeOf(const std::vector<Eigen::Vector3i>& appeared, const std::vector<Eigen::Vector3i>& vanished) {
  std::map<std::tuple<int, int, int>, float> sorted;
  for (const Eigen::Vector3i& v : appeared) sorted[{v.x(), v.y(), v.z()}] = 0.9f;
  for (const Eigen::Vector3i& v : vanished) sorted[{v.x(), v.y(), v.z()}] = -0.9f;
  GeometryChange change;
  change.voxel_size = kVoxel;
  for (const auto& [key, delta] : sorted) {
    change.changed_voxels.emplace_back(std::get<0>(key), std::get<1>(key), std::get<2>(key));
    change.changed_deltas.push_back(delta);
  }
  return change;
}

int Count(const std::vector<ObjectChange>& objects, ObjectState state) {
  return static_cast<int>(
      std::count_if(objects.begin(), objects.end(), [state](const ObjectChange& o) { return o.state == state; }));
}

// A removal and a new object, and no move.
void ExpectRemovalAndNew(const std::vector<ObjectChange>& objects) {
  EXPECT_EQ(Count(objects, ObjectState::kMoved), 0);
  EXPECT_EQ(Count(objects, ObjectState::kRemoved), 1);
  EXPECT_EQ(Count(objects, ObjectState::kNew), 1);
}

const ObjectChange* First(const std::vector<ObjectChange>& objects, ObjectState state) {
  const auto it =
      std::find_if(objects.begin(), objects.end(), [state](const ObjectChange& o) { return o.state == state; });
  return it == objects.end() ? nullptr : &*it;
}

TEST(GeometryObjects, ChangedVoxelsClusterBySignAndGap) {
  std::vector<Eigen::Vector3i> appeared = BoxSurface({0, 0, 0}, 3, 3, 3);
  const std::vector<Eigen::Vector3i> second = BoxSurface({4, 0, 0}, 3, 3, 3);  // one free voxel between
  appeared.insert(appeared.end(), second.begin(), second.end());
  const std::vector<Eigen::Vector3i> vanished = BoxSurface({0, 3, 0}, 3, 3, 3);  // touching the first block
  const GeometryChange change = ChangeOf(appeared, vanished);

  const std::vector<VoxelCluster> apart = ClusterChangedVoxels(change, true, 1);
  ASSERT_EQ(apart.size(), 2u);
  EXPECT_EQ(apart[0].points.size(), 26u);  // a 3x3x3 box's surface
  EXPECT_EQ(apart[1].points.size(), 26u);
  EXPECT_NEAR(apart[0].box.min().x(), 0.0, 1e-6);
  EXPECT_NEAR(apart[0].box.max().x(), 2 * kVoxel, 1e-6);
  EXPECT_NEAR(apart[0].mean_change, 0.9, 1e-6);
  ASSERT_EQ(ClusterChangedVoxels(change, true, 2).size(), 1u);  // the one-voxel gap bridged
  const std::vector<VoxelCluster> gone = ClusterChangedVoxels(change, false, 1);
  ASSERT_EQ(gone.size(), 1u);  // touching an appeared block, yet a cluster of its own
  EXPECT_NEAR(gone[0].Centroid().y(), 4 * kVoxel, 1e-6);
}

TEST(GeometryObjects, AnObjectTurnedAndMovedIsOneMoveWithItsRotation) {
  // Long and thin (2.4 x 0.6 m): unturned, the two footprints would cross and barely overlap.
  const std::vector<Eigen::Vector3i> before = BoxSurface({0, 0, 0}, 12, 3, 5, true);
  const std::vector<Eigen::Vector3i> after = Turned(BoxSurface({20, 0, 0}, 12, 3, 5, true), {20, 0, 0});
  const std::vector<ObjectChange> objects =
      GeometryObjects(ChangeOf(after, before), {}, {}, {}, {}, GeometryObjectOptions());
  ASSERT_EQ(objects.size(), 1u);
  const ObjectChange& moved = objects[0];
  EXPECT_EQ(moved.state, ObjectState::kMoved);
  EXPECT_TRUE(moved.class_agnostic);
  EXPECT_EQ(moved.label, kClassAgnosticLabel);
  ASSERT_TRUE(moved.before && moved.after);
  // 4 m along x, and the box's centroid turned about the pivot: the registration follows the turn.
  EXPECT_GT((*moved.after - *moved.before).head<2>().norm(), 2.5);
  const double yaw = std::atan2(moved.rotation(1, 0), moved.rotation(0, 0)) * 180.0 / M_PI;
  EXPECT_NEAR(std::abs(yaw), 90.0, 10.0) << yaw;
  EXPECT_NEAR(moved.box_before.max().z(), 4 * kVoxel, 1e-6);
  EXPECT_FALSE(moved.box_after.isEmpty());
  EXPECT_GT(moved.confidence, 0.5);
}

TEST(GeometryObjects, OtherShapesTopsAndFarMovesAreRemovedAndNew) {
  const std::vector<Eigen::Vector3i> before = BoxSurface({0, 0, 0}, 6, 4, 5);
  GeometryObjectOptions options;
  // Taller by 3 voxels: the tops differ by 0.6 m. Twice as tall, the shapes alone would still overlap enough.
  std::vector<ObjectChange> objects =
      GeometryObjects(ChangeOf(BoxSurface({20, 0, 0}, 6, 4, 8), before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kRemoved), 1);
  EXPECT_EQ(Count(objects, ObjectState::kNew), 1);
  GeometryObjectOptions no_top = options;
  no_top.max_top_difference_m = 1000.0;
  EXPECT_EQ(Count(GeometryObjects(ChangeOf(BoxSurface({20, 0, 0}, 6, 4, 10), before), {}, {}, {}, {}, no_top),
                  ObjectState::kMoved),
            1);
  objects = GeometryObjects(ChangeOf(BoxSurface({20, 0, 0}, 6, 4, 10), before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kRemoved), 1);
  EXPECT_EQ(Count(objects, ObjectState::kNew), 1);
  // As tall but three times as long: the shapes do not overlap enough.
  objects = GeometryObjects(ChangeOf(BoxSurface({20, 0, 0}, 18, 4, 5), before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kMoved), 0);
  // The same shape 10 m away: beyond max_move_m (8 m) ...
  objects = GeometryObjects(ChangeOf(BoxSurface({50, 0, 0}, 6, 4, 5), before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kMoved), 0);
  EXPECT_EQ(Count(objects, ObjectState::kNew), 1);
  // ... and within it when it is raised to 12 m.
  options.max_move_m = 12.0;
  objects = GeometryObjects(ChangeOf(BoxSurface({50, 0, 0}, 6, 4, 5), before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kMoved), 1);
  const ObjectChange* moved = First(objects, ObjectState::kMoved);
  ASSERT_NE(moved, nullptr);
  EXPECT_NEAR((*moved->after - *moved->before).x(), 10.0, 1e-6);
  EXPECT_NEAR(moved->weighted_distance, options.physical_weight * 10.0 / 12.0, 1e-6);  // the shapes overlap fully
}

// A long object with a cab (2 m high over its first half, 0.8 m over the rest) moved 6 m, seen from its cab's end
// before (its first 5 voxels of side, and its tops) and from its far end after (from its 15th voxel on): each
// centroid leans to the end its patrol saw. Centroid onto centroid the shapes overlap by about 0.42 (turned about, too
// little as well); at the best shift of up to 3 voxels each way, by about 0.58: a move only with the search.
TEST(GeometryObjects, AMoveSeenFromEachEndIsFoundBySearchingTheShift) {
  const auto seen = [](const std::vector<Eigen::Vector3i>& voxels, int origin_x, int first_x, int last_x) {
    std::vector<Eigen::Vector3i> kept;
    for (const Eigen::Vector3i& v : voxels) {
      const int x = v.x() - origin_x;
      const bool top = v.z() == 7 || (v.z() == 3 && x >= 10);
      if (top || (x >= first_x && x <= last_x)) kept.push_back(v);
    }
    return kept;
  };
  const std::vector<Eigen::Vector3i> before = seen(BoxSurface({0, 0, 0}, 20, 4, 8, true), 0, 0, 4);
  const std::vector<Eigen::Vector3i> after = seen(BoxSurface({30, 0, 0}, 20, 4, 8, true), 30, 14, 19);
  GeometryObjectOptions options;
  std::vector<ObjectChange> objects = GeometryObjects(ChangeOf(after, before), {}, {}, {}, {}, options);
  ASSERT_EQ(Count(objects, ObjectState::kMoved), 1);
  EXPECT_EQ(objects.size(), 1u);
  EXPECT_NEAR(First(objects, ObjectState::kMoved)->confidence, 0.9 * 0.58, 0.9 * 0.02);  // change 0.9 x the overlap
  options.shape_search_m = 0.0;
  objects = GeometryObjects(ChangeOf(after, before), {}, {}, {}, {}, options);
  EXPECT_EQ(Count(objects, ObjectState::kMoved), 0);
  EXPECT_EQ(Count(objects, ObjectState::kRemoved), 1);
  EXPECT_EQ(Count(objects, ObjectState::kNew), 1);
}

// A search of more than ten shape tolerances each way is refused, naming the key: its steps are at least half a
// tolerance, so this bounds the shifts tried.
TEST(GeometryObjects, AShiftSearchOfOverTenTolerancesIsRefused) {
  ChangeOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.geometry_objects.shape_search_m = 3.5;  // the tolerance is 0.3 m
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("change.geometry_objects.shape_search_m = 3.5"), std::string::npos) << error;
  options.geometry_objects.shape_tolerance_m = 0.4;
  EXPECT_TRUE(options.IsValid(&error)) << error;
}

// A crate's near side and its top, seen apart (two voxels between them): one object, not two.
TEST(GeometryObjects, ClustersStackedInOneFootprintAreOneObject) {
  std::vector<Eigen::Vector3i> appeared;
  for (int x = 0; x < 6; ++x) {
    for (int z = 0; z < 4; ++z) appeared.emplace_back(x, 0, z);  // the side, 0.8 m high
    for (int y = 0; y < 5; ++y) appeared.emplace_back(x, y, 6);  // the top at 1.2 m
  }
  appeared.emplace_back(20, 0, 0);  // a speck elsewhere stays apart (and too small)
  const std::vector<ObjectChange> objects =
      GeometryObjects(ChangeOf(appeared, {}), {}, {}, {}, {}, GeometryObjectOptions());
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_NEAR(objects[0].box_after.max().z(), 6 * kVoxel, 1e-6);
  EXPECT_NEAR(objects[0].box_after.min().z(), 0.0, 1e-6);
  EXPECT_NEAR(objects[0].after->y(), 2 * kVoxel, 1e-6);  // the centre of the footprint the top spans
}

TEST(GeometryObjects, SpecksAndStructureAreNoObjects) {
  GeometryObjectOptions options;
  const std::vector<Eigen::Vector3i> speck = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // 3 voxels
  const std::vector<Eigen::Vector3i> wall = BoxSurface({10, 0, 0}, 70, 1, 10);   // 14 m long
  std::vector<Eigen::Vector3i> appeared = speck;
  appeared.insert(appeared.end(), wall.begin(), wall.end());
  EXPECT_TRUE(GeometryObjects(ChangeOf(appeared, {}), {}, {}, {}, {}, options).empty());
  options.max_size_m = 20.0;
  EXPECT_EQ(Count(GeometryObjects(ChangeOf(appeared, {}), {}, {}, {}, {}, options), ObjectState::kNew), 1);
  options.enabled = false;
  EXPECT_TRUE(GeometryObjects(ChangeOf(appeared, {}), {}, {}, {}, {}, options).empty());
}

TEST(GeometryObjects, ADetectedObjectLeavesItsClusterToTheDetector) {
  const std::vector<Eigen::Vector3i> removed = BoxSurface({0, 0, 0}, 5, 5, 5);
  const std::vector<Eigen::Vector3i> added = BoxSurface({0, 45, 0}, 5, 5, 5);  // 9 m off: not a move
  const GeometryChange change = ChangeOf(added, removed);
  MapObject detected;
  detected.centroid = Eigen::Vector3d(0.4, 9.4, 0.4);  // inside the added box
  std::vector<ObjectChange> objects = GeometryObjects(change, {}, {}, {}, {detected}, GeometryObjectOptions());
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].state, ObjectState::kRemoved);
  // The same object in the prior patrol's map says nothing about the current cluster.
  objects = GeometryObjects(change, {}, {}, {detected}, {}, GeometryObjectOptions());
  EXPECT_EQ(objects.size(), 2u);
  // Just outside the box, within the margin.
  detected.centroid = Eigen::Vector3d(0.4, 8.7, 0.4);
  EXPECT_EQ(GeometryObjects(change, {}, {}, {}, {detected}, GeometryObjectOptions()).size(), 1u);
}

// Stereo often sees a vehicle only by its ends: a changed end lies 2 m from the vehicle's centroid, but inside its
// box, and is left to the detector; a crate beside the vehicle, beyond the margin, is not.
TEST(GeometryObjects, AClusterInsideADetectedObjectsBoxIsLeftToTheDetector) {
  const std::vector<Eigen::Vector3i> end = BoxSurface({0, 0, 0}, 2, 9, 7);     // 0.4 x 1.8 x 1.4 m at x = 0
  const std::vector<Eigen::Vector3i> crate = BoxSurface({0, 14, 0}, 5, 5, 5);  // 1 m beside it
  MapObject vehicle;
  vehicle.centroid = Eigen::Vector3d(2.0, 0.8, 0.7);
  vehicle.box_min = Eigen::Vector3d(0.0, 0.0, 0.0);
  vehicle.box_max = Eigen::Vector3d(4.2, 1.8, 1.5);
  std::vector<ObjectChange> objects =
      GeometryObjects(ChangeOf(end, {}), {}, {}, {}, {vehicle}, GeometryObjectOptions());
  EXPECT_TRUE(objects.empty());
  objects = GeometryObjects(ChangeOf(crate, {}), {}, {}, {}, {vehicle}, GeometryObjectOptions());
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].state, ObjectState::kNew);
  // Without the box (an object mapped without depth), only its centroid counts, even for a cluster at the origin.
  vehicle.box_min = vehicle.box_max = Eigen::Vector3d::Zero();
  const std::vector<Eigen::Vector3i> corner = BoxSurface({0, 0, 0}, 2, 3, 3);
  EXPECT_EQ(GeometryObjects(ChangeOf(corner, {}), {}, {}, {}, {vehicle}, GeometryObjectOptions()).size(), 1u);
}

// From two evidence grids: a crate put down (its surface occupied now, free before) and another taken away.
TEST(GeometryObjects, DiffGridsSignsEachChangedVoxel) {
  EvidenceGridData before, after;
  before.voxel_size = after.voxel_size = kVoxel;
  const std::vector<Eigen::Vector3i> put = BoxSurface({0, 0, 0}, 5, 5, 5);
  const std::vector<Eigen::Vector3i> taken = BoxSurface({0, 60, 0}, 5, 5, 5);
  std::map<std::tuple<int, int, int>, std::pair<VoxelEvidence, VoxelEvidence>> voxels;
  const auto add = [&voxels](const Eigen::Vector3i& v, bool occupied_before, bool occupied_after) {
    const auto evidence = [&v](bool occupied) {
      return VoxelEvidence{v.x(), v.y(), v.z(), static_cast<std::uint16_t>(occupied ? 8 : 0),
                           static_cast<std::uint16_t>(occupied ? 0 : 8)};
    };
    voxels[{v.x(), v.y(), v.z()}] = {evidence(occupied_before), evidence(occupied_after)};
  };
  for (const Eigen::Vector3i& v : put) add(v, false, true);
  for (const Eigen::Vector3i& v : taken) add(v, true, false);
  for (const auto& [key, pair] : voxels) {
    before.voxels.push_back(pair.first);
    after.voxels.push_back(pair.second);
  }
  GeometryDiffOptions diff;
  diff.surface_tolerance_voxels = 0;
  diff.max_differing_share = 1.0;  // a scene of changes only
  GeometryChange change;
  ASSERT_TRUE(DiffGrids(before, after, diff, &change));
  ASSERT_EQ(change.changed_voxels.size(), put.size() + taken.size());
  ASSERT_EQ(change.changed_deltas.size(), change.changed_voxels.size());
  for (std::size_t i = 0; i < change.changed_voxels.size(); ++i) {
    EXPECT_EQ(change.changed_deltas[i] > 0.0f, change.changed_voxels[i].y() < 30) << i;
  }
  const std::vector<ObjectChange> objects =
      GeometryObjects(change, LookupIn(before), LookupIn(after), {}, {}, GeometryObjectOptions());
  ASSERT_EQ(objects.size(), 2u);
  const ObjectChange* removed = First(objects, ObjectState::kRemoved);
  const ObjectChange* added = First(objects, ObjectState::kNew);
  ASSERT_TRUE(removed != nullptr && added != nullptr);
  EXPECT_NEAR(removed->before->y(), 12.4, 1e-6);
  EXPECT_NEAR(added->after->x(), 0.4, 1e-6);
  EXPECT_NEAR(added->confidence, 1.0, 1e-6);
}

// Every voxel of x in [-10, 40], y in [-10, 20], z in [0, 10] observed 8 times: occupied in `solid` boxes and on the
// ground (z = 0), free elsewhere; those in `unseen` boxes not observed at all.
EvidenceGridData Observed(const std::vector<Eigen::AlignedBox3i>& solid,
                          const std::vector<Eigen::AlignedBox3i>& unseen = {}) {
  EvidenceGridData grid;
  grid.voxel_size = kVoxel;
  for (int x = -10; x <= 40; ++x) {
    for (int y = -10; y <= 20; ++y) {
      for (int z = 0; z <= 10; ++z) {
        const auto holds = [&](const Eigen::AlignedBox3i& box) { return box.contains(Eigen::Vector3i(x, y, z)); };
        if (std::any_of(unseen.begin(), unseen.end(), holds)) continue;
        bool occupied = z == 0;
        for (const Eigen::AlignedBox3i& box : solid) occupied = occupied || box.contains(Eigen::Vector3i(x, y, z));
        grid.voxels.push_back(
            {x, y, z, static_cast<std::uint16_t>(occupied ? 8 : 0), static_cast<std::uint16_t>(occupied ? 0 : 8)});
      }
    }
  }
  return grid;  // x, then y, then z ascending: the grid's order
}

// The class-agnostic objects between two grids of a scene of changes only (most of its surfaces differ, so the check
// of the poses is off).
std::vector<ObjectChange> ObjectsBetween(const EvidenceGridData& before, const EvidenceGridData& after,
                                         const GeometryObjectOptions& options = GeometryObjectOptions()) {
  GeometryDiffOptions diff;
  diff.max_differing_share = 1.0;
  GeometryChange change;
  EXPECT_TRUE(DiffGrids(before, after, diff, &change));
  return GeometryObjects(change, LookupIn(before), LookupIn(after), {}, {}, options);
}

// A vehicle (21 x 9 x 7 voxels) moved 2 m along its length: only its two ends change, yet the completed objects are
// the whole vehicle where it was and where it is.
TEST(GeometryObjects, AnObjectMovedLessThanItsLengthIsCompletedFromEachGrid) {
  const EvidenceGridData before = Observed({Eigen::AlignedBox3i(Eigen::Vector3i(0, 0, 1), Eigen::Vector3i(20, 8, 7))});
  const EvidenceGridData after = Observed({Eigen::AlignedBox3i(Eigen::Vector3i(10, 0, 1), Eigen::Vector3i(30, 8, 7))});
  GeometryObjectOptions options;
  std::vector<ObjectChange> objects = ObjectsBetween(before, after, options);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].state, ObjectState::kMoved);
  EXPECT_NEAR(objects[0].before->x(), 2.0, 1e-6);  // the vehicle's centre, x 0..4 m
  EXPECT_NEAR(objects[0].after->x(), 4.0, 1e-6);
  EXPECT_NEAR(objects[0].before->y(), 0.8, 1e-6);
  EXPECT_NEAR(objects[0].box_after.min().z(), kVoxel, 1e-6);  // the ground left out
  // The changed ends alone put the vehicle's centre 1.2 m off at each end.
  options.complete_objects = false;
  objects = ObjectsBetween(before, after, options);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_GT(std::abs(objects[0].before->x() - 2.0), 1.0);
  // Grown past max_size_m the object stays its changed part.
  options.complete_objects = true;
  options.max_size_m = 3.0;
  objects = ObjectsBetween(before, after, options);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_GT(std::abs(objects[0].before->x() - 2.0), 1.0);
}

// A 2 x 2 m patch of ground seen one voxel higher in the second patrol (what a pose correction to within half a voxel
// can leave) and a new crate. The patch's voxels change, above and below, but lie on the ground: no object. The
// crate, three voxels tall, is the one new object.
TEST(GeometryObjects, ASheetOfGroundSeenAVoxelHigherIsNoObject) {
  const auto grid = [](bool after) {
    EvidenceGridData g;
    g.voxel_size = kVoxel;
    for (int x = -10; x <= 40; ++x) {
      for (int y = -10; y <= 20; ++y) {
        for (int z = 0; z <= 10; ++z) {
          const bool patch = after && x >= 0 && x < 10 && y >= 0 && y < 10;
          const bool crate = after && x >= 25 && x < 28 && y >= 0 && y < 3 && z >= 1 && z <= 3;
          const bool occupied = z == (patch ? 1 : 0) || crate;
          g.voxels.push_back(
              {x, y, z, static_cast<std::uint16_t>(occupied ? 8 : 0), static_cast<std::uint16_t>(occupied ? 0 : 8)});
        }
      }
    }
    return g;
  };
  const std::vector<ObjectChange> objects = ObjectsBetween(grid(false), grid(true));
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].state, ObjectState::kNew);
  EXPECT_NEAR(objects[0].after->x(), 5.2, 1e-6);  // the crate, x 5.0-5.4 m
}

}  // namespace
}  // namespace patrolmap::change
