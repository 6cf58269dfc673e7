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
    // The smaller crate, of the same label and texture, differs only in its top.
    ASSERT_FALSE(changes.empty());
    EXPECT_EQ(changes[0].state, state) << side;
    EXPECT_EQ(changes.size(), state == ObjectState::kMoved ? 1u : 2u) << side;
    ObjectDiffOptions no_top_gate;
    no_top_gate.max_top_difference_m = 1.0;
    EXPECT_EQ(DiffObjects(prior, current, no_top_gate)[0].state, ObjectState::kMoved) << side;
  }
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

}  // namespace
}  // namespace patrolmap::change
