#include "patrolmap/change/change_detector.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "change/fixtures.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::Depth;
using testing_fixtures::GridOf;
using testing_fixtures::kAtOrigin;
using testing_fixtures::kCamera;
using testing_fixtures::Patrol;

std::vector<std::string> IdsOf(const GeometryChange& geometry, const std::vector<ObjectChange>& objects) {
  std::vector<std::string> ids;
  for (const GeometryRegion& region : geometry.regions) ids.push_back(GeometryChangeId(region.centroid));
  for (const ObjectChange& object : objects) ids.push_back(ObjectChangeId(object) + ":" + ToString(object.state));
  return ids;
}

// The report after the flight and a check while flying run the same steps: at the end of the flight, with the
// same rays per voxel, they find the same regions and objects (the detected crate new, first).
TEST(ChangeDetector, TheReportAndACheckWhileFlyingFindTheSameChanges) {
  ChangeOptions options;
  const EvidenceGrid before = GridOf(Depth(5.0f, false), options), after = GridOf(Depth(5.0f, true), options);
  const PatrolRecord prior = Patrol("before", before, false), current = Patrol("after", after, true);
  ChangeDetector detector(prior, options);
  ChangeReport report;
  detector.Compare(current, {}, &report);
  EXPECT_EQ(report.prior_flight, "before");
  EXPECT_EQ(report.current_flight, "after");
  EXPECT_TRUE(report.geometry_compared && report.objects_compared);
  EXPECT_FALSE(report.geometry.poses_disagree);
  ASSERT_FALSE(report.geometry.regions.empty());
  ASSERT_FALSE(report.objects.empty());
  EXPECT_EQ(report.objects[0].state, ObjectState::kNew);
  EXPECT_EQ(report.objects[0].label, "crate");
  EXPECT_EQ(report.geometry.depth_current, "images");

  PatrolRecord live = current;
  live.grid = EvidenceGridData();  // read in place from `after`
  const LiveFindings found = detector.Check(live, &after);
  EXPECT_EQ(found.held, HoldReason::kNone);
  EXPECT_TRUE(found.geometry_compared);
  EXPECT_FALSE(found.shift_changed);
  EXPECT_EQ(IdsOf(found.geometry, found.objects), IdsOf(report.geometry, report.objects));
  // Without depth while flying only the object maps are compared.
  const LiveFindings no_depth = detector.Check(live, nullptr);
  EXPECT_FALSE(no_depth.geometry_compared);
  ASSERT_EQ(no_depth.objects.size(), 1u);
  EXPECT_EQ(no_depth.objects[0].label, "crate");
}

// Surfaces that differ almost everywhere mean the poses disagree: neither comparison then compares the objects
// those poses placed, and a check while flying says it holds its changes back.
TEST(ChangeDetector, PosesThatDisagreeHoldObjectsBack) {
  ChangeOptions options;
  options.alignment.max_shift_m = 0.0;  // no shift can explain it
  const EvidenceGrid before = GridOf(Depth(5.0f, false), options), after = GridOf(Depth(3.0f, true), options);
  const PatrolRecord prior = Patrol("before", before, false), current = Patrol("after", after, true);
  ChangeDetector detector(prior, options);
  ChangeReport report;
  detector.Compare(current, {}, &report);
  EXPECT_TRUE(report.geometry.poses_disagree);
  EXPECT_TRUE(report.objects.empty());
  EXPECT_FALSE(report.objects_compared);
  PatrolRecord live = current;
  live.grid = EvidenceGridData();
  const LiveFindings found = detector.Check(live, &after);
  EXPECT_EQ(found.held, HoldReason::kPosesDisagree);
  EXPECT_TRUE(found.objects.empty());
}

// A finished patrol whose poses are 0.6 m (three voxels) off along the view is moved onto the prior (sideways the
// wider far wall fits either way), and then nothing differs; a check while flying takes the same shift and keeps it.
TEST(ChangeDetector, APatrolShiftedByWholeVoxelsIsMovedOntoThePrior) {
  ChangeOptions options;
  const EvidenceGrid before = GridOf(Depth(5.0f, false), options), after = GridOf(Depth(5.6f, false), options);
  const PatrolRecord prior = Patrol("before", before, false);
  PatrolRecord current = Patrol("after", after, false);
  ChangeDetector detector(prior, options);
  const GridShift shift = detector.Align(&current);
  ASSERT_TRUE(shift.applied);
  EXPECT_EQ(shift.voxels.z(), -3);
  EXPECT_NEAR(current.views[0].position.z(), -0.6, 1e-9);
  ChangeReport report;
  detector.Compare(current, {}, &report);
  EXPECT_TRUE(report.geometry.regions.empty());
  PatrolRecord live = Patrol("after", after, false);
  live.grid = EvidenceGridData();
  const LiveFindings found = detector.Check(live, &after);
  EXPECT_TRUE(found.shift_changed);
  EXPECT_EQ(detector.shift(), shift.voxels);
  EXPECT_TRUE(found.geometry.regions.empty());
  EXPECT_FALSE(detector.Check(live, &after).shift_changed);  // kept, not taken again
}

}  // namespace
}  // namespace patrolmap::change
