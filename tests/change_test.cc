// Unit tests of the change stage: evidence grid, geometry regions, object
// maps, object states, rigid registration and appearance change.
#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

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

TEST(EvidenceGrid, MemoryBoundDropsNewVoxelsAndCountsThem) {
  EvidenceGridOptions options;
  options.max_voxels = 3;
  EvidenceGrid grid(options);
  grid.TraceRay(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 0.0, 0.0), true);
  EXPECT_EQ(grid.voxel_count(), 3u);
  EXPECT_EQ(grid.dropped_updates(), 8);
}

// Depth of a flat wall at x = 10 seen by a camera at the origin looking along +x.
cv::Mat WallDepth(const CameraIntrinsics& camera, double distance) {
  cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(distance));
  return depth;
}

CameraPoseSample LookingAlongX(const Eigen::Vector3d& position) {
  // Camera z (forward) = world x, camera x (right) = world -y, camera y (down) = world -z.
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);
  r.col(1) = Eigen::Vector3d(0, 0, -1);
  r.col(2) = Eigen::Vector3d(1, 0, 0);
  return {0, position, Eigen::Quaterniond(r)};
}

const CameraIntrinsics kCamera{40.0, 40.0, 31.5, 23.5, 64, 48};

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

EvidenceGridData GridOf(const std::vector<std::pair<Eigen::Vector3i, std::pair<int, int>>>& cells) {
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

TEST(GeometryChange, AppearedCubeIsOneRegionAndUnobservedSpaceIsNoChange) {
  std::vector<std::pair<Eigen::Vector3i, std::pair<int, int>>> before, after;
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
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), GeometryDiffOptions{}, &change));
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_EQ(change.regions[0].voxels, 48);
  EXPECT_EQ(change.regions[0].appeared, 48);
  EXPECT_EQ(change.regions[0].vanished, 0);
  EXPECT_NEAR(change.regions[0].centroid.x(), 0.3, 1e-9);
  EXPECT_NEAR(change.regions[0].centroid.z(), 0.4, 1e-9);
  EXPECT_EQ(change.changed_voxels.size(), 48u);
  EXPECT_EQ(change.compared_voxels, 48 + 10 + 1);
}

TEST(GeometryChange, DistantClustersStaySeparateAndOverlappingRegionsMerge) {
  std::vector<std::pair<Eigen::Vector3i, std::pair<int, int>>> before, after;
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
  ASSERT_TRUE(DiffGrids(GridOf(before), GridOf(after), GeometryDiffOptions{}, &change));
  ASSERT_EQ(change.regions.size(), 2u);
  EXPECT_EQ(change.regions[0].voxels, 40);
  EXPECT_EQ(change.regions[0].vanished, 40);
  EXPECT_EQ(change.regions[1].voxels, 12);
}

TEST(GeometryChange, DifferentVoxelSizesCannotBeCompared) {
  EvidenceGridData a, b;
  a.voxel_size = 0.2, b.voxel_size = 0.25;
  GeometryChange change;
  EXPECT_FALSE(DiffGrids(a, b, GeometryDiffOptions{}, &change));
  EXPECT_FALSE(DiffGrids(EvidenceGridData{}, EvidenceGridData{}, GeometryDiffOptions{}, &change));
}

std::vector<Eigen::Vector3f> BoxPoints(const Eigen::Vector3f& centre, float size, float spacing) {
  std::vector<Eigen::Vector3f> points;
  const int n = static_cast<int>(size / spacing);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const float a = -size / 2 + i * spacing, b = -size / 2 + j * spacing;
      for (const Eigen::Vector3f& p :
           {Eigen::Vector3f(-size / 2, a, b), Eigen::Vector3f(a, -size / 2, b), Eigen::Vector3f(a, b, size / 2)}) {
        points.push_back(centre + p);
      }
    }
  }
  return points;
}

TEST(PointPairs, FractionOfNearestNeighboursWithinTheThreshold) {
  const std::vector<Eigen::Vector3f> box = BoxPoints(Eigen::Vector3f(1, 2, 0.5), 1.0f, 0.1f);
  EXPECT_DOUBLE_EQ(PairFraction(box, box, 0.01), 1.0);
  std::vector<Eigen::Vector3f> shifted = box;
  for (Eigen::Vector3f& p : shifted) p.x() += 1.5f;
  EXPECT_DOUBLE_EQ(PairFraction(shifted, box, 0.1), 0.0);
  EXPECT_DOUBLE_EQ(PairFraction({}, box, 0.1), 0.0);
  std::vector<Eigen::Vector3f> filtered = box;
  VoxelFilter(0.25, &filtered);
  EXPECT_LT(filtered.size(), box.size() / 3);
  EXPECT_GT(filtered.size(), 20u);
}

TEST(Registration, RecoversTheRotationOfAMovedObject) {
  cv::RNG rng(4);
  std::vector<Eigen::Vector3f> before;
  for (int i = 0; i < 400; ++i) {  // an elongated, lopsided cloud (a vehicle with a cab)
    const float x = static_cast<float>(rng.uniform(-2.0, 2.0));
    const float z = static_cast<float>(rng.uniform(0.0, x > 1.0f ? 1.8 : 1.2));
    before.emplace_back(x, static_cast<float>(rng.uniform(-0.8, 0.8)), z);
  }
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3f> after;
  for (const Eigen::Vector3f& p : before)
    after.push_back((rotation * p.cast<double>()).cast<float>() + Eigen::Vector3f(5, 1, 0));
  const Eigen::Matrix3d found = RegisterRotation(before, after);
  EXPECT_LT((found - rotation).norm(), 1e-6);
  EXPECT_TRUE(RegisterRotation({}, after).isIdentity());
}

ObjectObservation Detection(const std::string& label, double confidence, const CameraPoseSample& pose,
                            const Eigen::Vector3d& world, double noise, cv::RNG* rng) {
  ObjectObservation o;
  o.label = label;
  o.confidence = confidence;
  const Eigen::Vector3d c =
      pose.ToCamera(world) + noise * Eigen::Vector3d(rng->gaussian(1), rng->gaussian(1), rng->gaussian(1));
  o.centroid_camera = c;
  const double u = kCamera.fx * c.x() / c.z() + kCamera.cx, v = kCamera.fy * c.y() / c.z() + kCamera.cy;
  const double half = kCamera.fx * 0.5 / c.z();
  o.box = cv::Rect2d(u - half, v - half, 2 * half, 2 * half);
  return o;
}

TEST(ObjectMap, DetectionsBecomeObjectsWithAccumulatedLabels) {
  ObjectMapOptions options;
  ObjectMapper mapper(options, kCamera);
  cv::RNG rng(7);
  const Eigen::Vector3d crate(10, 0.5, 0.5), barrel(12, -1.0, 0.5), ghost(9, 2.0, 0.5);
  for (int frame = 0; frame < 12; ++frame) {
    const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0.2 * frame, 0, 1.5));
    std::vector<ObjectObservation> detections = {
        Detection("crate", 0.8, pose, crate, 0.1, &rng),
        Detection(frame % 4 == 0 ? "barrel" : "crate", 0.6, pose, barrel, 0.1, &rng)};
    if (frame == 5) detections.push_back(Detection("crate", 0.9, pose, ghost, 0.1, &rng));  // one false detection
    mapper.AddFrame(detections, pose, cv::Mat(), cv::Mat());
  }
  const std::vector<MapObject> objects = mapper.Finish();
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_TRUE(objects[0].confirmed && objects[1].confirmed);
  EXPECT_FALSE(objects[2].confirmed);  // the single false detection is below min_detections
  EXPECT_EQ(objects[2].detections, 1);
  EXPECT_EQ(objects[0].label, "crate");
  EXPECT_NEAR(objects[0].confidence, 0.8, 1e-9);
  EXPECT_EQ(objects[0].detections, 12);
  EXPECT_LT((objects[0].centroid - crate).norm(), 0.1);
  // The second object was called a barrel 3 times and a crate 9 times: crate wins, its mean confidence stays.
  EXPECT_EQ(objects[1].label, "crate");
  EXPECT_NEAR(objects[1].confidence, 0.6, 1e-9);
  ASSERT_EQ(objects[1].labels.size(), 2u);
  EXPECT_EQ(mapper.associations(), 25);
}

TEST(ObjectMap, PointPairTestSeparatesNeighboursTheGateCannot) {
  ObjectMapOptions options;
  options.centroid_gate_m = 1.5;
  ObjectMapper mapper(options, kCamera);
  cv::RNG rng(2);
  // Two crates 0.9 m apart, inside each other's centroid gate, each seen with its depth.
  const Eigen::Vector3d a(8, 0.45, 0.5), b(8, -0.45, 0.5);
  const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0, 0, 0.5));
  for (int frame = 0; frame < 6; ++frame) {
    cv::Mat depth(kCamera.height, kCamera.width, CV_32FC1, cv::Scalar(0));
    std::vector<ObjectObservation> detections;
    for (const Eigen::Vector3d& centre : {a, b}) {
      ObjectObservation o = Detection("crate", 0.7, pose, centre, 0.0, &rng);
      const cv::Rect box = cv::Rect(o.box) & cv::Rect(0, 0, kCamera.width, kCamera.height);
      depth(box).setTo(centre.x() - 0.4);  // their front faces
      detections.push_back(o);
    }
    mapper.AddFrame(detections, pose, depth, cv::Mat());
  }
  const std::vector<MapObject> objects = mapper.Finish();
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_FALSE(objects[0].points.empty());
  EXPECT_EQ(objects[0].detections + objects[1].detections, 12);
}

PatrolRecord Patrol(const std::vector<std::pair<std::string, Eigen::Vector3d>>& objects) {
  PatrolRecord record;
  record.camera = kCamera;
  record.has_objects = true;
  for (double x = 0; x <= 10; x += 1.0) record.views.push_back(LookingAlongX(Eigen::Vector3d(x - 6, 0, 1)));
  for (std::size_t i = 0; i < objects.size(); ++i) {
    MapObject o;
    o.id = static_cast<int>(i);
    o.label = objects[i].first;
    o.confidence = 0.8;
    o.detections = 10;
    o.centroid = objects[i].second;
    o.box_min = o.centroid - Eigen::Vector3d::Constant(0.5);
    o.box_max = o.centroid + Eigen::Vector3d::Constant(0.5);
    record.objects.push_back(o);
  }
  return record;
}

TEST(ObjectStates, PersistentMovedRemovedNewAndUnobserved) {
  const PatrolRecord prior = Patrol({{"crate", {10, 0, 0.5}},
                                     {"vehicle", {12, 2, 0.75}},
                                     {"barrel", {9, -1, 0.5}},
                                     {"crate", {-20, 0, 0.5}}});  // behind every view
  const PatrolRecord current =
      Patrol({{"crate", {10.2, 0.1, 0.5}}, {"vehicle", {12, -1.5, 0.75}}, {"barrel", {14, 1, 0.5}}});
  ObjectDiffOptions options;
  options.max_move_m = 4.0;
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, options);
  std::map<std::string, int> counts;
  for (const ObjectChange& c : changes) ++counts[ToString(c.state)];
  EXPECT_EQ(counts["persistent"], 1);
  EXPECT_EQ(counts["moved"], 1);    // the vehicle, 3.5 m
  EXPECT_EQ(counts["removed"], 1);  // the barrel at (9, -1): the barrel at (14, 1) is 5.4 m away, beyond max_move
  EXPECT_EQ(counts["new"], 1);
  EXPECT_EQ(counts["unobserved"], 1);  // the crate behind the flight
  for (const ObjectChange& c : changes) {
    if (c.state == ObjectState::kMoved) {
      EXPECT_EQ(c.label, "vehicle");
      EXPECT_NEAR((*c.after - *c.before).norm(), 3.5, 1e-9);
    }
    if (c.state == ObjectState::kRemoved) {
      EXPECT_GE(c.expected_detections, options.min_expected_detections);
    }
    EXPECT_GE(c.confidence, 0.0);
    EXPECT_LE(c.confidence, 1.0);
  }
}

TEST(ObjectStates, UnconfirmedObjectsAreNeverReportedButExplainLaterSightings) {
  PatrolRecord prior = Patrol({{"crate", {10, 0, 0.5}}, {"barrel", {12, 2, 0.5}}});
  prior.objects[0].confirmed = false;  // seen once in the prior patrol
  prior.objects[1].confirmed = false;
  PatrolRecord current = Patrol({{"crate", {10.1, 0, 0.5}}, {"vehicle", {14, -2, 0.75}}});
  current.objects[1].confirmed = false;
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);  // no removed barrel, no new vehicle
  EXPECT_EQ(changes[0].state, ObjectState::kPersistent);
  EXPECT_EQ(changes[0].label, "crate");
}

TEST(ObjectStates, AnOccupiedWallHidesAPriorObject) {
  const PatrolRecord prior = Patrol({{"crate", {10, 0, 0.5}}});
  PatrolRecord current = Patrol({});
  current.grid.voxel_size = 0.2;
  for (int y = -20; y <= 20; ++y) {
    for (int z = 0; z <= 15; ++z) current.grid.voxels.push_back({35, y, z, 9, 0});  // a wall at x = 7 m
  }
  EXPECT_EQ(CoveringViews(prior.objects[0], current, ObjectDiffOptions{}), 0);
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].state, ObjectState::kUnobserved);
}

TEST(ObjectStates, AViewCoversAnObjectWithHalfItsBoxInTheImage) {
  const PatrolRecord patrol = Patrol({{"crate", {10, 0, 0.5}}, {"crate", {10, -8.125, 0.5}}});
  const CameraPoseSample view = LookingAlongX(Eigen::Vector3d(0, 0, 0.5));
  EXPECT_NEAR(VisibleFraction(patrol.objects[0], kCamera, view), 1.0, 1e-9);
  // Centred on the image's right edge (u = 64 at 10 m is y = -8.125): about half of it inside.
  EXPECT_NEAR(VisibleFraction(patrol.objects[1], kCamera, view), 0.5, 0.05);
  EXPECT_EQ(VisibleFraction(patrol.objects[0], kCamera, LookingAlongX(Eigen::Vector3d(10.2, 0, 0.5))),
            0.0);  // inside it
}

TEST(ObjectStates, RemovedNeedsTheDetectionsTheCurrentViewsWouldHaveGiven) {
  MapObject object;
  object.detections = 10;
  EXPECT_DOUBLE_EQ(ExpectedDetections(object, 5, 4), 8.0);
  object.detections = 2;
  EXPECT_DOUBLE_EQ(ExpectedDetections(object, 8, 8), 2.0);
  EXPECT_DOUBLE_EQ(ExpectedDetections(object, 0, 3), 3.0);  // no own view covered it: one per view
  // A crate the prior patrol glimpsed in 3 views and detected 3 times: gone when the current patrol's 3 views
  // of its place show nothing; unknown when only 2 did (2 expected detections, under min_expected_detections).
  PatrolRecord prior = Patrol({{"crate", {10, 0, 0.5}}});
  prior.views.resize(3);
  prior.objects[0].detections = 3;
  PatrolRecord current = Patrol({});
  current.views.resize(3);
  std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].state, ObjectState::kRemoved);
  EXPECT_DOUBLE_EQ(changes[0].expected_detections, 3.0);
  EXPECT_NEAR(changes[0].confidence, 0.8 * (1 - std::exp(-3.0)), 1e-9);
  current.views.resize(2);
  changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].state, ObjectState::kUnobserved);
}

// Points every 0.1 m on the surface of an axis-aligned cube standing on the ground at `centre` (x, y).
std::vector<Eigen::Vector3f> CubePoints(const Eigen::Vector2d& centre, double side) {
  std::vector<Eigen::Vector3f> points;
  const int n = static_cast<int>(std::lround(side / 0.1));
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      for (int k = 0; k <= n; ++k) {
        if (i != 0 && i != n && j != 0 && j != n && k != 0 && k != n) continue;  // inside
        points.emplace_back(static_cast<float>(centre.x() - side / 2 + i * 0.1),
                            static_cast<float>(centre.y() - side / 2 + j * 0.1), static_cast<float>(k * 0.1));
      }
    }
  }
  return points;
}

// A patrol holding one crate: a cube of side `side` standing at (x, 0), with its surface points and box.
PatrolRecord CratePatrol(double x, double side) {
  PatrolRecord record = Patrol({{"crate", {x, 0, side / 2}}});
  record.objects[0].points = CubePoints({x, 0}, side);
  record.objects[0].box_min = Eigen::Vector3d(x - side / 2, -side / 2, 0);
  record.objects[0].box_max = Eigen::Vector3d(x + side / 2, side / 2, side);
  return record;
}

TEST(ObjectStates, AMovedObjectKeepsItsTopHeight) {
  const PatrolRecord prior = CratePatrol(10, 1.0);
  for (const auto& [side, state] : {std::pair{1.0, ObjectState::kMoved}, std::pair{0.8, ObjectState::kRemoved}}) {
    const PatrolRecord current = CratePatrol(12, side);
    const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
    // The smaller crate, centred on the bigger one, lies within the shape test's 0.15 m: only its top tells.
    ASSERT_FALSE(changes.empty());
    EXPECT_EQ(changes[0].state, state) << side;
    EXPECT_EQ(changes.size(), state == ObjectState::kMoved ? 1u : 2u) << side;
    ObjectDiffOptions no_top_gate;
    no_top_gate.max_top_difference_m = 1.0;
    EXPECT_EQ(DiffObjects(prior, current, no_top_gate)[0].state, ObjectState::kMoved) << side;
  }
}

// Paper 000's point-pair test after the move: a crate 2 m away of the same label, texture and top height
// but another shape (a slab 2 m long, 0.2 m deep) is not the crate moved; with no shape rule it would be.
TEST(ObjectStates, AMovedObjectKeepsItsShape) {
  const PatrolRecord prior = CratePatrol(10, 1.0);
  PatrolRecord current = Patrol({{"crate", {12, 0, 0.5}}});
  MapObject& slab = current.objects[0];
  for (int i = 0; i <= 20; ++i) {
    for (int k = 0; k <= 10; ++k) {
      for (const float y : {-0.1f, 0.1f}) slab.points.emplace_back(11.0f + 0.1f * i, y, 0.1f * k);
    }
  }
  slab.box_min = Eigen::Vector3d(11, -0.1, 0);
  slab.box_max = Eigen::Vector3d(13, 0.1, 1);
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 2u);
  const auto count = [&changes](ObjectState state) {
    return std::count_if(changes.begin(), changes.end(), [state](const ObjectChange& c) { return c.state == state; });
  };
  EXPECT_EQ(count(ObjectState::kRemoved), 1);  // the crate
  EXPECT_EQ(count(ObjectState::kNew), 1);      // the slab
  ObjectDiffOptions any_shape;
  any_shape.min_shape_overlap = 0.0;
  const std::vector<ObjectChange> loose = DiffObjects(prior, current, any_shape);
  ASSERT_EQ(loose.size(), 1u);
  EXPECT_EQ(loose[0].state, ObjectState::kMoved);
}

TEST(ObjectStates, AnObjectSeenFromOneSideBeforeIsPersistentWhenSeenWhole) {
  PatrolRecord prior = Patrol({{"barrel", {10, 0, 0.5}}});
  for (const Eigen::Vector3f& p : CubePoints({10, 0}, 1.0)) {
    if (p.x() < 9.55f) prior.objects[0].points.push_back(p);  // only the face towards the flight
  }
  PatrolRecord current = Patrol({{"barrel", {10.1, 0, 0.5}}});
  current.objects[0].points = CubePoints({10.1, 0}, 1.0);
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].state, ObjectState::kPersistent);
}

TEST(ObjectStates, OnlyAnObjectThatMayBeTheMovedOneIsLookedThrough) {
  // A crate stood at x = 10; the current patrol has a new crate at x = 7 in front of that place, whose
  // voxels fill the line of sight. Of the same size it may be the crate moved (looked through, paired as a
  // move); taller, it is another crate that hides the place: the prior one is unobserved, not removed.
  const PatrolRecord prior = CratePatrol(10, 1.0);
  for (const auto& [side, state] : {std::pair{1.0, ObjectState::kMoved}, std::pair{1.4, ObjectState::kUnobserved}}) {
    PatrolRecord current = CratePatrol(7, side);
    current.grid.voxel_size = 0.2;
    for (int x = 33; x <= 37; ++x) {
      for (int y = -5; y <= 5; ++y) {
        for (int z = 0; z <= 7; ++z) current.grid.voxels.push_back({x, y, z, 9, 0});
      }
    }
    std::sort(current.grid.voxels.begin(), current.grid.voxels.end(), VoxelBefore);
    const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
    ASSERT_FALSE(changes.empty());
    EXPECT_EQ(changes[0].state, state) << side;
  }
}

TEST(ObjectStates, AnObjectWhosePlaceWentUnseenCanStillHaveMoved) {
  // Behind every view of the current patrol, the crate left its place for one 4 m away.
  const PatrolRecord prior = Patrol({{"crate", {-20, 0, 0.5}}});
  const PatrolRecord current = Patrol({{"crate", {-16, 0, 0.5}}});
  const std::vector<ObjectChange> changes = DiffObjects(prior, current, ObjectDiffOptions{});
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].state, ObjectState::kMoved);
  EXPECT_EQ(changes[0].covering_views, 0);
}

// A textured scene, its view after a lighting change, and SIFT features of both.
struct Pair {
  KeyFrameView prior, current;
};

KeyFrameView Describe(const cv::Mat& image) {
  KeyFrameView view;
  view.image = image;
  cv::SIFT::create(500)->detectAndCompute(image, cv::noArray(), view.keypoints, view.descriptors);
  return view;
}

cv::Mat Scene(int seed) {
  cv::Mat image(120, 160, CV_8UC1);
  cv::RNG rng(seed);
  image.setTo(120);
  for (int i = 0; i < 90; ++i) {
    const cv::Point a(rng.uniform(0, 160), rng.uniform(0, 120));
    cv::rectangle(image, a, a + cv::Point(rng.uniform(3, 18), rng.uniform(3, 18)), cv::Scalar(rng.uniform(0, 255)),
                  cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.7);
  return image;
}

cv::Mat Relit(const cv::Mat& image, double gain, double gamma, double shift_px) {
  cv::Mat moved, out;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, shift_px, 0, 1, 0);
  cv::warpAffine(image, moved, m, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  moved.convertTo(out, CV_32F, 1.0 / 255);
  cv::pow(out, gamma, out);
  out.convertTo(out, CV_8U, 255 * gain);
  return out;
}

TEST(Appearance, LightingOnlyGivesNoRegion) {
  const cv::Mat scene = Scene(1);
  const AppearanceChange change =
      DetectAppearanceChange(Describe(scene), Describe(Relit(scene, 0.8, 1.3, 3.0)), AppearanceOptions{});
  ASSERT_TRUE(change.registered);
  EXPECT_GT(change.inliers, 30);
  EXPECT_TRUE(change.regions.empty());
  EXPECT_NEAR(change.homography.at<double>(0, 2), 3.0, 0.5);
}

TEST(Appearance, AnAddedObjectIsARegionInBothImages) {
  const cv::Mat scene = Scene(2);
  cv::Mat current = Relit(scene, 1.1, 0.9, -2.0);
  const cv::Rect object(60, 40, 26, 22);
  current(object).setTo(30);
  cv::rectangle(current, object, cv::Scalar(220), 2);
  const AppearanceChange change = DetectAppearanceChange(Describe(scene), Describe(current), AppearanceOptions{});
  ASSERT_TRUE(change.registered);
  ASSERT_FALSE(change.regions.empty());
  const AppearanceRegion& region = change.regions[0];
  EXPECT_GT((region.current_box & object).area(), 0.6 * object.area());
  EXPECT_LT(region.current_box.area(), 2.0 * object.area());
  EXPECT_NEAR(region.prior_box.x, region.current_box.x + 2, 2);  // the prior view is 2 px to the right
  EXPECT_GT(region.score, 0.0);
  EXPECT_GT(region.unmatched_prior_features, 0);  // the prior texture under the object no longer matches
}

TEST(Appearance, ARegionWhoseFeaturesStillMatchIsParallaxNotChange) {
  // A textured block of the scene seen 7 px off the rest (a nearer facade, off the registered plane): its
  // pixels differ beyond the search radius, but its features match their prior selves.
  cv::Mat scene = Scene(5);
  cv::Mat texture(60, 80, CV_8UC1);
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.2);
  texture.copyTo(scene(cv::Rect(40, 30, 80, 60)));
  cv::Mat current = scene.clone();
  const cv::Rect block(50, 30, 60, 60);
  scene(block - cv::Point(7, 0)).copyTo(current(block));
  AppearanceOptions keep_all;
  keep_all.min_unmatched_share = 0.0;
  keep_all.max_shifted_similarity = 1.1;
  const AppearanceChange all = DetectAppearanceChange(Describe(scene), Describe(current), keep_all);
  ASSERT_TRUE(all.registered);
  ASSERT_FALSE(all.regions.empty());  // the registration cannot fit both planes: pixels differ somewhere
  for (const AppearanceRegion& r : all.regions) {
    EXPECT_GT(r.prior_features + r.current_features, 0);
    EXPECT_LT(r.unmatched_prior_features + r.unmatched_current_features, 0.5 * (r.prior_features + r.current_features));
  }
  EXPECT_TRUE(DetectAppearanceChange(Describe(scene), Describe(current), AppearanceOptions{}).regions.empty());
  // Each test alone drops them too: the features still match, and the content is there a few pixels off.
  AppearanceOptions features_only = keep_all, shift_only = keep_all;
  features_only.min_unmatched_share = 0.5;
  shift_only.max_shifted_similarity = AppearanceOptions{}.max_shifted_similarity;
  EXPECT_TRUE(DetectAppearanceChange(Describe(scene), Describe(current), features_only).regions.empty());
  EXPECT_LT(DetectAppearanceChange(Describe(scene), Describe(current), shift_only).regions.size(), all.regions.size());
}

TEST(Appearance, ARegionIsKeptAtItsUnmatchedShareAndDroppedBelowIt) {
  AppearanceOptions options;  // min_unmatched_share 0.5
  AppearanceRegion region;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));  // no features: nothing says parallax
  region.prior_features = 6, region.current_features = 4;
  region.unmatched_prior_features = 3, region.unmatched_current_features = 2;  // 5 of 10: exactly the share
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  region.unmatched_current_features = 1;  // 4 of 10
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  region.unmatched_prior_features = 0, region.unmatched_current_features = 3;  // 3 of 10: both sides count
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 0.3;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 0.0;  // keeps every region, even one whose features all match
  region.unmatched_current_features = 0;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 1.0;  // keeps only regions where nothing matches
  region.unmatched_prior_features = 6, region.unmatched_current_features = 3;
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  region.unmatched_current_features = 4;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
}

// Matches alone do not register a pair: the homography needs min_inliers inliers. Two halves of the scene
// moved apart (two planes) match everywhere, but one homography fits one half; with min_inliers between
// the two counts the pair is not registered and yields no region.
TEST(Appearance, APairNeedsItsInliersNotOnlyItsMatches) {
  const cv::Mat prior = Scene(5);
  cv::Mat current = prior.clone();
  const cv::Rect right(80, 0, 80, 120);
  Scene(5)(right - cv::Point(20, 0)).copyTo(current(right));  // the right half shows what lay 20 px left
  const AppearanceChange loose = DetectAppearanceChange(Describe(prior), Describe(current), AppearanceOptions{});
  ASSERT_TRUE(loose.registered);
  ASSERT_LT(loose.inliers, 0.8 * loose.matches) << "one homography should not fit both halves";
  AppearanceOptions strict;
  strict.min_inliers = (loose.inliers + loose.matches) / 2;
  const AppearanceChange change = DetectAppearanceChange(Describe(prior), Describe(current), strict);
  EXPECT_EQ(change.matches, loose.matches);
  EXPECT_FALSE(change.registered);
  EXPECT_TRUE(change.regions.empty());
}

TEST(Appearance, UnrelatedImagesAreNotRegistered) {
  const AppearanceChange change = DetectAppearanceChange(Describe(Scene(3)), Describe(Scene(4)), AppearanceOptions{});
  EXPECT_FALSE(change.registered);
  EXPECT_TRUE(change.regions.empty());
  EXPECT_FALSE(DetectAppearanceChange(KeyFrameView{}, KeyFrameView{}, AppearanceOptions{}).registered);
}

}  // namespace
}  // namespace patrolmap::change
