#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "change/fixtures.h"
#include "patrolmap/change/report.h"
#include "test_util.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::kCamera;
using testing_fixtures::LookingAlongX;

// A patrol that kept two frames: frame 0 from the origin, frame 1 from 3 m further back and 2 m to the left,
// both looking along x at the box 10 m ahead.
PatrolRecord Patrol(const std::string& flight, TimestampNs offset_ns) {
  PatrolRecord record;
  record.flight = flight;
  record.camera = kCamera;
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", cv::Mat(48, 64, CV_8UC1, cv::Scalar(128)), jpeg);
  for (int i = 0; i < 2; ++i) {
    RouteFrame frame;
    frame.timestamp_ns = offset_ns + i;
    frame.frame_index = i;
    frame.pose = LookingAlongX(Eigen::Vector3d(-3.0 * i, 2.0 * i, 0.0));
    frame.jpeg = jpeg;
    record.route.push_back(frame);
    record.views.push_back(*frame.pose);
  }
  return record;
}

struct Scene {
  graph::TopoMap map;
  ChangeReport report;
};

// Object 7 of patrol b, a crate at 10 m, is new.
Scene NewCrate() {
  Scene scene;
  PatrolRecord prior = Patrol("a", 0), current = Patrol("b", 100);
  MapObject crate;
  crate.id = 7;
  crate.label = "crate";
  crate.box_min = Eigen::Vector3d(9.5, -0.5, -0.5);
  crate.box_max = Eigen::Vector3d(10.5, 0.5, 0.5);
  current.objects.push_back(crate);
  scene.map.SetPatrol(prior);
  scene.map.SetPatrol(current);
  scene.report.prior_flight = "a";
  scene.report.current_flight = "b";
  scene.report.objects_compared = true;
  ObjectChange change;
  change.state = ObjectState::kNew;
  change.label = "crate";
  change.confidence = 0.8;
  change.current_id = 7;
  change.after = Eigen::Vector3d(10.0, 0.0, 0.0);
  scene.report.objects.push_back(change);
  return scene;
}

int RedPixels(const cv::Mat& bgr) {
  int red = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      red += p[2] > 180 && p[1] < 80 && p[0] < 80;
    }
  }
  return red;
}

TEST(ReportItems, ANewObjectIsShownFromBothPatrolsBestFrames) {
  const Scene scene = NewCrate();
  const std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  ASSERT_EQ(items.size(), 1u);
  const ChangeItem& item = items[0];
  EXPECT_EQ(item.id, "object-p-1-c7");
  EXPECT_EQ(item.number, 1);
  EXPECT_EQ(item.kind, "object");
  EXPECT_EQ(item.state, "new");
  EXPECT_EQ(item.after.flight, "b");
  EXPECT_EQ(item.after.frame_index, 0);  // the nearer, straight-on view
  EXPECT_EQ(item.after.timestamp_ns, 100);
  EXPECT_EQ(item.before.flight, "a");  // where it now stands, seen by the prior patrol
  EXPECT_EQ(item.before.frame_index, 0);
  ASSERT_FALSE(item.after.image.empty());
  EXPECT_EQ(std::max(item.after.image.cols, item.after.image.rows), ReportOptions().crop_size_px);
  EXPECT_GT(RedPixels(item.after.image), 50);  // the box is outlined
}

// Whether the geometry was compared where the crate stands: unknown when no grids were compared, false when they were
// but no compared voxel lies there (no depth reached it), true when one does.
TEST(ReportItems, SaysWhetherTheGeometryWasComparedWhereAChangeStands) {
  Scene scene = NewCrate();
  EXPECT_FALSE(ReportItems(scene.report, scene.map)[0].compared_in_3d.has_value());
  scene.report.geometry_compared = true;
  scene.report.geometry.compared_cells = {{3, 0, 0}};  // 3-4 m along x: two cells short of the crate
  EXPECT_EQ(ReportItems(scene.report, scene.map)[0].compared_in_3d, std::optional<bool>(false));
  EXPECT_NE(ToHtml(scene.report, scene.map, ReportItems(scene.report, scene.map), std::nullopt, "")
                .find("not compared in 3D"),
            std::string::npos);
  scene.report.geometry.compared_cells = {{9, -1, -1}};  // beside the crate's cell (10, 0, 0)
  EXPECT_EQ(ReportItems(scene.report, scene.map)[0].compared_in_3d, std::optional<bool>(true));
}

// A voxel the current patrol found occupied between the first frame and the crate: the other frame shows it.
TEST(ReportItems, AFrameWhoseViewTheGridBlocksIsPassedOver) {
  Scene scene = NewCrate();
  PatrolRecord current = *scene.map.Patrol("b");
  current.grid.voxel_size = 0.2;
  VoxelEvidence wall;
  wall.x = 25;  // 5 m ahead of the first frame, beside the second one's line of sight
  wall.hits = 6;
  current.grid.voxels.push_back(wall);
  scene.map.SetPatrol(current);
  const std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(items[0].after.frame_index, 1);
  EXPECT_EQ(items[0].before.frame_index, 0);  // the prior patrol's grid is empty
}

TEST(ReportItems, NothingShowsAChangeOutOfEveryFramesView) {
  Scene scene = NewCrate();
  PatrolRecord current = *scene.map.Patrol("b");
  current.objects[0].box_min = Eigen::Vector3d(-10.5, -0.5, -0.5);  // behind the camera
  current.objects[0].box_max = Eigen::Vector3d(-9.5, 0.5, 0.5);
  scene.map.SetPatrol(current);
  const std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(items[0].after.frame_index, -1);
  EXPECT_TRUE(items[0].after.image.empty());
}

// A change along the route, seen in two pairs of route frames: the label says how far depth changed too.
TEST(ReportItems, ARouteChangeSaysInHowManyViewsAndHowMuchOfItDepthMarked) {
  Scene scene = NewCrate();
  scene.report.objects.clear();
  scene.report.route.compared = true;
  for (int i = 0; i < 2; ++i) {
    RoutePair pair;
    pair.prior = pair.current = i;
    AppearanceRegion region;
    region.current_box = region.prior_box = cv::Rect(10, 10, 20, 16);
    pair.appearance.registered = true;
    pair.appearance.regions.push_back(region);
    scene.report.route.pairs.push_back(pair);
  }
  RouteChange change;
  change.views = {{0, 0}, {1, 0}};
  change.marked_share = 0.454;
  change.confidence = RouteConfidence(0.2, change.marked_share, 2);
  scene.report.route.changes.push_back(change);
  std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(items[0].kind, "appearance");
  EXPECT_EQ(items[0].label, "seen in 2 views, depth changed over 45 % of it");
  EXPECT_DOUBLE_EQ(items[0].confidence, change.confidence);
  scene.report.route.changes[0].marked_share = 0.0;  // a log without poses: appearance alone
  items = ReportItems(scene.report, scene.map);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(items[0].label, "seen in 2 views");
}

TEST(ChangeReportPage, HasAMarkerARowAndBothPicturesPerChange) {
  const Scene scene = NewCrate();
  const std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  const std::string html = ToHtml(scene.report, scene.map, items, std::nullopt, "pictures");
  EXPECT_NE(html.find("class='marker' data-id='object-p-1-c7'"), std::string::npos);
  EXPECT_NE(html.find("<tr id='row-object-p-1-c7'"), std::string::npos);
  EXPECT_NE(html.find("data-src='pictures/object-p-1-c7-before.jpg'"), std::string::npos);
  EXPECT_NE(html.find("data-src='pictures/object-p-1-c7-after.jpg'"), std::string::npos);
  EXPECT_NE(html.find("1 change."), std::string::npos);
  EXPECT_NE(html.find("not in the prior patrol's map"), std::string::npos);
  EXPECT_EQ(html.find("Camera poses from"), std::string::npos);  // the scene's records do not say
  ChangeReport posed = scene.report;
  posed.pose_prior = kPosesFromStateEstimate;
  posed.pose_current = kPosesFromGps;
  EXPECT_NE(ToHtml(posed, scene.map, items, std::nullopt, "pictures")
                .find("Camera poses from the log's state estimate before, GPS and the IMU's attitude now."),
            std::string::npos);
  // Without a folder the pictures are embedded.
  EXPECT_NE(ToHtml(scene.report, scene.map, items, std::nullopt, "").find("src='data:image/png;base64,"),
            std::string::npos);
}

TEST(ChangeReportGeo, PutsTheChangeAtItsLongitudeAndLatitude) {
  const Scene scene = NewCrate();
  const std::vector<ChangeItem> items = ReportItems(scene.report, scene.map);
  GeoReference geo;
  geo.origin_latitude = 47.0;
  geo.origin_longitude = 8.0;
  const nlohmann::json document = nlohmann::json::parse(ToGeoJson(scene.report, scene.map, items, geo));
  EXPECT_EQ(document["type"], "FeatureCollection");
  const nlohmann::json& point = document["features"].back();
  EXPECT_EQ(point["properties"]["id"], "object-p-1-c7");
  const Eigen::Vector2d expected = geo.LatitudeLongitude(Eigen::Vector3d(10.0, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(point["geometry"]["coordinates"][0].get<double>(), expected.y());  // longitude first
  EXPECT_DOUBLE_EQ(point["geometry"]["coordinates"][1].get<double>(), expected.x());
  EXPECT_NEAR(expected.y() - 8.0, 10.0 / (6378137.0 * std::cos(47.0 * M_PI / 180.0)) * 180.0 / M_PI, 1e-12);
  const std::string kml = ToKml(scene.report, scene.map, items, geo, "pictures");
  EXPECT_NE(kml.find("<Placemark id=\"object-p-1-c7\">"), std::string::npos);
  EXPECT_NE(kml.find("pictures/object-p-1-c7-after.jpg"), std::string::npos);
}

TEST(WriteChangeReport, WritesThePicturesBesideThePage) {
  testing::TempDir dir;
  const Scene scene = NewCrate();
  ASSERT_TRUE(WriteChangeReport(scene.report, scene.map, dir / "out").ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "out/changes_images/object-p-1-c7-after.jpg"));
  EXPECT_FALSE(cv::imread(dir / "out/changes_images/object-p-1-c7-before.jpg").empty());
  const nlohmann::json json = nlohmann::json::parse(testing::ReadText(dir / "out/changes.json"));
  EXPECT_EQ(json["changes"][0]["after"]["image"], "changes_images/object-p-1-c7-after.jpg");
  EXPECT_FALSE(std::filesystem::exists(dir / "out/changes.geojson"));  // no GPS
}

// changes.json's reader gives back what its writer wrote; a file that is not one is refused naming it and what is
// wrong.
TEST(ReadChangesJson, ReadsBackTheFlightsObjectsAndEntriesWritten) {
  testing::TempDir dir;
  const Scene scene = NewCrate();
  std::vector<ChangeItem> items;
  ASSERT_TRUE(WriteChangeReport(scene.report, scene.map, dir / "out", &items).ok());
  ChangesFile file;
  ASSERT_TRUE(ReadChangesJson(dir / "out/changes.json", &file).ok());
  EXPECT_EQ(file.prior_flight, "a");
  EXPECT_EQ(file.current_flight, "b");
  ASSERT_TRUE(file.objects_compared);
  ASSERT_EQ(file.objects.size(), 1u);
  EXPECT_EQ(file.objects[0].state, "new");
  EXPECT_EQ(file.objects[0].label, "crate");
  EXPECT_FALSE(file.objects[0].before);
  EXPECT_TRUE(file.objects[0].after->isApprox(Eigen::Vector3d(10.0, 0.0, 0.0)));
  ASSERT_EQ(file.entries.size(), items.size());
  EXPECT_EQ(file.entries[0].id, items[0].id);
  EXPECT_TRUE(file.entries[0].position->isApprox(*items[0].position));
}

TEST(ReadChangesJson, RefusesAFileThatIsNotAChangeReportNamingIt) {
  testing::TempDir dir;
  const Scene scene = NewCrate();
  ASSERT_TRUE(WriteChangeReport(scene.report, scene.map, dir / "out").ok());
  const std::string path = dir / "out/changes.json";
  nlohmann::json written = nlohmann::json::parse(testing::ReadText(path));
  const auto refused = [&](const std::string& text, const std::string& why) {
    testing::WriteText(path, text);
    ChangesFile file;
    const Status status = ReadChangesJson(path, &file);
    EXPECT_FALSE(status.ok()) << why;
    EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
    EXPECT_NE(status.message().find(why), std::string::npos) << status.message();
  };
  refused("{\"format\": \"patrolmap.changes\", ", "not JSON");
  refused("[1, 2]", "not a patrolmap change report");
  nlohmann::json damaged = written;
  damaged["changes"][0]["position"] = {1.0, 2.0};
  refused(damaged.dump(), "'position' is not null or three numbers");
  damaged = written;
  damaged["objects"][0].erase("state");
  refused(damaged.dump(), "malformed change report");
  damaged = written;
  damaged["changes"] = "none";
  refused(damaged.dump(), "'changes' is not an array");
  ChangesFile file;
  EXPECT_EQ(ReadChangesJson(dir / "missing.json", &file).code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace patrolmap::change
