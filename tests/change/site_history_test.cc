#include <gtest/gtest.h>

#include "change/fixtures.h"
#include "patrolmap/change/site_history.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::kCamera;
using testing_fixtures::LookingAlongX;

// Patrol `n` of a series, flown from the origin looking along x; with `crate`, the crate (site object 1) at x.
PatrolRecord Patrol(int n, std::optional<double> crate, bool looked) {
  PatrolRecord record;
  record.flight = "day-" + std::to_string(n);
  record.camera = kCamera;
  record.has_objects = true;
  if (looked) {
    for (int k = 0; k < 5; ++k) record.views.push_back(LookingAlongX(Eigen::Vector3d(0.0, 0.1 * k, 0.0)));
  }
  if (crate) {
    MapObject o;
    o.id = n;  // the object maps number their objects anew each patrol
    o.site_id = 1;
    o.label = "crate";
    o.detections = 10;
    o.centroid = Eigen::Vector3d(*crate, 0.0, 0.0);
    o.box_min = o.centroid - Eigen::Vector3d::Constant(0.5);
    o.box_max = o.centroid + Eigen::Vector3d::Constant(0.5);
    record.objects.push_back(o);
  }
  return record;
}

// A crate there since patrol 1, moved at patrol 4, gone at 7 (where a patrol looked), back at 9; patrol 8 flew
// elsewhere and says nothing of it.
TEST(SiteHistory, AnObjectsFirstSightingMovesRemovalAndReturnInTheOrderFlown) {
  graph::TopoMap map;
  const std::optional<double> none;
  const std::vector<std::pair<std::optional<double>, bool>> series = {{10.0, true}, {10.0, true},  {10.2, true},
                                                                      {13.0, true}, {13.0, true},  {13.0, true},
                                                                      {none, true}, {none, false}, {13.0, true}};
  for (std::size_t i = 0; i < series.size(); ++i)
    map.SetPatrol(Patrol(static_cast<int>(i) + 1, series[i].first, series[i].second));
  std::vector<SiteObjectHistory> history;
  ASSERT_TRUE(SiteHistory(map, ObjectDiffOptions(), {}, &history).ok());
  ASSERT_EQ(history.size(), 1u);
  const SiteObjectHistory& crate = history[0];
  EXPECT_EQ(crate.id, 1);
  EXPECT_EQ(crate.sightings, 7);
  ASSERT_EQ(crate.events.size(), 4u);
  EXPECT_EQ(crate.events[0].what, "first seen");
  EXPECT_EQ(crate.events[0].patrol, 1);
  EXPECT_EQ(crate.events[1].what, "moved");  // 10.2 m at patrol 3 is within match_distance_m of 10
  EXPECT_EQ(crate.events[1].flight, "day-4");
  EXPECT_NEAR(crate.events[1].from->x(), 10.2, 1e-9);
  EXPECT_NEAR(crate.events[1].to->x(), 13.0, 1e-9);
  EXPECT_EQ(crate.events[2].what, "not seen");
  EXPECT_EQ(crate.events[2].patrol, 7);
  EXPECT_EQ(crate.events[3].what, "seen again");
  EXPECT_EQ(crate.events[3].patrol, 9);

  SiteHistoryFilter filter;
  filter.from = "day-5";
  filter.to = "day-7";
  ASSERT_TRUE(SiteHistory(map, ObjectDiffOptions(), filter, &history).ok());
  ASSERT_EQ(history.size(), 1u);
  ASSERT_EQ(history[0].events.size(), 2u);  // first seen (in the span) at 5, not seen at 7
  EXPECT_EQ(history[0].events[1].what, "not seen");
  filter = SiteHistoryFilter();
  filter.near = Eigen::Vector2d(50.0, 0.0);
  ASSERT_TRUE(SiteHistory(map, ObjectDiffOptions(), filter, &history).ok());
  EXPECT_TRUE(history.empty());
  filter = SiteHistoryFilter();
  filter.from = "day-99";
  EXPECT_NE(SiteHistory(map, ObjectDiffOptions(), filter, &history).message().find("'day-99' is not in the map"),
            std::string::npos);
}

}  // namespace
}  // namespace patrolmap::change
