#include <gtest/gtest.h>

#include "patrolmap/change/site_objects.h"

namespace patrolmap::change {
namespace {

MapObject Object(int id, int site_id) {
  MapObject o;
  o.id = id;
  o.label = "crate";
  o.site_id = site_id;
  return o;
}

ObjectChange Change(ObjectState state, int prior_id, int current_id) {
  ObjectChange c;
  c.state = state;
  c.prior_id = prior_id;
  c.current_id = current_id;
  return c;
}

// Persistent and moved objects keep their prior object's site id; a new one takes the next free id, and so does an
// object the comparison did not judge. The report's changes are then named by them.
TEST(SiteObjects, AnObjectThatStayedOrMovedKeepsItsIdAndANewOneTakesTheNext) {
  PatrolRecord prior, current;
  prior.objects = {Object(1, 5), Object(2, 6), Object(3, 9)};
  current.objects = {Object(10, -1), Object(11, -1), Object(12, -1), Object(13, 4)};
  ChangeReport report;
  report.objects = {Change(ObjectState::kPersistent, 1, 10), Change(ObjectState::kMoved, 2, 11),
                    Change(ObjectState::kNew, -1, 12), Change(ObjectState::kRemoved, 3, -1)};
  int last = 9;
  CarrySiteObjects(prior, report, &current, &last);
  EXPECT_EQ(current.objects[0].site_id, 5);
  EXPECT_EQ(current.objects[1].site_id, 6);
  EXPECT_EQ(current.objects[2].site_id, 10);
  EXPECT_EQ(current.objects[3].site_id, 11);  // not judged: its own id, whatever it held
  EXPECT_EQ(last, 11);
  NameSiteObjects(prior, current, &report);
  EXPECT_EQ(report.objects[0].site_id, 5);
  EXPECT_EQ(report.objects[1].site_id, 6);
  EXPECT_EQ(report.objects[2].site_id, 10);
  EXPECT_EQ(report.objects[3].site_id, 9);  // removed: the prior object's
}

// A map's patrols are numbered in the order flown, and numbered objects keep their ids.
TEST(SiteObjects, AMapsObjectsAreNumberedInTheOrderFlown) {
  graph::TopoMap map;
  PatrolRecord first, second;
  first.flight = "a";
  first.objects = {Object(1, -1), Object(2, -1)};
  second.flight = "b";
  second.objects = {Object(1, 1), Object(2, -1)};
  map.SetPatrol(first);
  map.SetPatrol(second);
  EXPECT_EQ(LargestSiteId(map), 1);
  NumberAllSiteObjects(&map);
  EXPECT_EQ(map.Patrol("a")->objects[0].site_id, 2);
  EXPECT_EQ(map.Patrol("a")->objects[1].site_id, 3);
  EXPECT_EQ(map.Patrol("b")->objects[0].site_id, 1);
  EXPECT_EQ(map.Patrol("b")->objects[1].site_id, 4);
}

}  // namespace
}  // namespace patrolmap::change
