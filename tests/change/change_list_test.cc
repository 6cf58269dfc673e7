#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "patrolmap/change/report.h"

namespace patrolmap::change {
namespace {

ChangeItem Item(const std::string& id, const std::string& kind, double confidence,
                const std::vector<Eigen::AlignedBox3d>& extent) {
  ChangeItem item;
  item.id = id;
  item.kind = kind;
  item.confidence = confidence;
  item.extent = extent;
  item.channels = {kind == "object" ? "detections" : kind};
  if (!extent.empty()) item.position = extent.back().center();
  return item;
}

Eigen::AlignedBox3d Box(double x, double y, double half) {
  return Eigen::AlignedBox3d(Eigen::Vector3d(x - half, y - half, 0.0), Eigen::Vector3d(x + half, y + half, 1.0));
}

// A crate moved from (10, 0) to (10, 4): the region it left, and the wall behind its old place that a camera at
// (0, 0) now sees through it, are the crate's entry; a region 5 m aside, and a bearing without depth, stand alone.
TEST(ChangeList, FindingsOfOneChangeAreOneEntry) {
  std::vector<ChangeItem> items;
  items.push_back(Item("object-p1-c2", "object", 0.8, {Box(10, 0, 0.4), Box(10, 4, 0.4)}));
  items.push_back(Item("geometry-5_0_0", "geometry", 0.5, {Box(10.3, 0.2, 0.3)}));
  items.push_back(Item("geometry-7_2_0", "geometry", 0.9, {Box(15, 5, 0.3)}));
  items[1].source = {"geometry", 0}, items[2].source = {"geometry", 1};
  ChangeItem wall = Item("appearance-f1-1", "appearance", 0.5, {});
  wall.position = Eigen::Vector3d(14, 0.1, 0.5);  // the line of sight passes the crate's old box
  wall.bearing = Bearing{Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitX()};
  wall.extent = {Eigen::AlignedBox3d(*wall.position, *wall.position)};
  items.push_back(wall);
  ChangeItem far = wall;
  far.id = "appearance-f2-2";
  far.position.reset();
  far.extent.clear();
  items.push_back(far);
  // Given last but an object: it leads.
  std::rotate(items.begin(), items.begin() + 1, items.end());
  const std::vector<ChangeItem> entries = FuseItems(items, 1.0);
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_EQ(entries[0].id, "object-p1-c2");
  ASSERT_EQ(entries[0].evidence.size(), 2u);
  EXPECT_EQ(entries[0].evidence[0].id, "geometry-5_0_0");
  EXPECT_EQ(entries[0].evidence[1].id, "appearance-f1-1");
  EXPECT_EQ(entries[0].channels, (std::vector<std::string>{"detections", "geometry", "appearance"}));
  EXPECT_NEAR(entries[0].confidence, 1.0 - 0.2 * 0.5 * 0.5, 1e-12);  // independent witnesses
  EXPECT_EQ(entries[1].id, "geometry-7_2_0");
  EXPECT_TRUE(entries[1].evidence.empty());
  EXPECT_EQ(entries[2].id, "appearance-f2-2");
  // Within 0.2 m nothing but the region touches the crate's boxes; the line of sight still crosses them.
  EXPECT_EQ(FuseItems(items, 0.2).size(), 3u);
  // Each region's id, whether it leads an entry or joined one.
  EXPECT_EQ(IdsOf(entries, "geometry", 2), (std::vector<std::string>{"geometry-5_0_0", "geometry-7_2_0"}));
}

}  // namespace
}  // namespace patrolmap::change
