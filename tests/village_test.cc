// The village simulator: routes, trajectories, objects, detector, depth and whole-log determinism.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/objects.h"
#include "patrolmap/sim/route.h"
#include "patrolmap/sim/village.h"
#include "test_util.h"

namespace patrolmap::sim {
namespace {

Route Preset(const std::string& name) {
  Route route;
  EXPECT_TRUE(RoutePreset(name, &route).ok());
  return route;
}

TEST(Routes, PresetLengthsMatchThePaperExperiments) {
  // Paper 002 §IV: double loop ~375 m, inner loop ~155 m, L-shape ~85 m.
  // Straight lengths 400, 142 and 85 m; each 90 degree corner of radius 3 m is 1.29 m shorter.
  EXPECT_NEAR(PathLength(Preset("double-loop"), 3.0), 400.0 - 8 * 1.288, 0.05);
  EXPECT_NEAR(PathLength(Preset("inner-loop"), 3.0), 142.0 - 4 * 1.288, 0.05);
  EXPECT_NEAR(PathLength(Preset("l-shape"), 3.0), 85.0 - 2 * 1.288, 0.05);
  Route route;
  EXPECT_EQ(RoutePreset("zigzag", &route).code(), StatusCode::kInvalidArgument);
}

TEST(Routes, WaypointFileErrorsNameFileAndLine) {
  testing::TempDir dir;
  testing::WriteText(dir / "w.csv", "# x,y\n0,0\n10,zero\n");
  Route route;
  const Status status = ReadWaypoints(dir / "w.csv", &route);
  EXPECT_NE(status.message().find("w.csv:3:"), std::string::npos) << status.message();
  testing::WriteText(dir / "w.csv", "0,0\n0,0\n");
  EXPECT_EQ(ReadWaypoints(dir / "w.csv", &route).code(), StatusCode::kDataLoss);
  testing::WriteText(dir / "w.csv", "0,0\n20,0\n20,10\n");
  ASSERT_TRUE(ReadWaypoints(dir / "w.csv", &route).ok());
  EXPECT_EQ(route.waypoints.size(), 3u);
  testing::WriteText(dir / "w.csv", "x,y\n0,0\n20,0\n");  // a header row
  ASSERT_TRUE(ReadWaypoints(dir / "w.csv", &route).ok());
  EXPECT_EQ(route.waypoints.size(), 2u);
  testing::WriteText(dir / "w.csv", "0,0\nx,y\n");  // ... only as the first
  EXPECT_NE(ReadWaypoints(dir / "w.csv", &route).message().find("w.csv:2:"), std::string::npos);
  testing::WriteText(dir / "w.csv", "0,0\n1e9,0\n");  // would render for days
  EXPECT_NE(ReadWaypoints(dir / "w.csv", &route).message().find("w.csv:2: a waypoint lies beyond 10000 m"),
            std::string::npos);
  testing::WriteText(dir / "w.csv", "0,0\n9000,0\n0,0\n9000,0\n0,0\n9000,0\n0,0\n");
  EXPECT_NE(ReadWaypoints(dir / "w.csv", &route).message().find("km long"), std::string::npos);
}

// Integrates the trajectory's own rates and compares them with its positions and headings.
TEST(FlyRoute, RatesAgreeWithPositionsAndTheLoopTurnsOnce) {
  SimulatedFlight flight;
  RouteOptions options;
  options.altitude_changes = 2;
  ASSERT_TRUE(FlyRoute(Preset("inner-loop"), options, &flight).ok());
  EXPECT_NEAR(flight.duration_s, 136.8 / 1.3, 8.0);  // mean speed 1.3 m/s with 10 % jitter
  const double dt = 0.005;
  double heading = flight.trajectory(0.0).heading;
  Eigen::Vector3d position = flight.trajectory(0.0).position;
  Eigen::Vector3d velocity = flight.trajectory(0.0).velocity;
  for (double t = 0.0; t + dt <= flight.duration_s; t += dt) {
    const PlatformState a = flight.trajectory(t), b = flight.trajectory(t + dt);
    heading += 0.5 * (a.yaw_rate + b.yaw_rate) * dt;
    position += 0.5 * (a.velocity + b.velocity) * dt;
    velocity += 0.5 * (a.acceleration + b.acceleration) * dt;
  }
  const PlatformState end = flight.trajectory(flight.duration_s);
  EXPECT_NEAR(heading - flight.trajectory(0.0).heading, 2 * M_PI, 0.02);  // one counter-clockwise loop
  EXPECT_NEAR(std::remainder(end.heading - heading, 2 * M_PI), 0.0, 0.02);
  EXPECT_LT((end.position - position).norm(), 0.3);
  EXPECT_LT((end.velocity - velocity).norm(), 0.05);
  EXPECT_NEAR(end.position.z(), 3.0, 3.0 + 1e-9);  // two changes of 1.5 m at most
}

TEST(Village, SameSeedSameWorldAndAlikeFacadesShareATexture) {
  const Village a = MakeVillage({3}), b = MakeVillage({3}), c = MakeVillage({4});
  ASSERT_EQ(a.scene.walls.size(), b.scene.walls.size());
  for (std::size_t i = 0; i < a.scene.walls.size(); ++i) EXPECT_EQ(a.scene.walls[i].start, b.scene.walls[i].start);
  EXPECT_NE(a.scene.walls.size() == c.scene.walls.size() && a.scene.walls[5].start == c.scene.walls[5].start, true);
  ASSERT_EQ(a.alike_walls.size(), 2u);
  for (const auto& [first, second] : a.alike_walls) {
    EXPECT_EQ(a.scene.walls[first].texture, a.scene.walls[second].texture);
  }
  EXPECT_GT(a.building_count, 30);
}

TEST(Objects, ChangesBetweenFlightsAccountForEveryObject) {
  const std::vector<WorldObject> first = PlaceObjects(20, 5);
  ASSERT_EQ(first.size(), 20u);
  std::vector<ObjectChange> changes;
  const std::vector<WorldObject> second = ChangeObjects(first, ChangeSpec{}, 77, &changes);
  int counts[4] = {0, 0, 0, 0};
  for (const ObjectChange& change : changes) ++counts[static_cast<int>(change.state)];
  const int persistent = counts[0], added = counts[1], removed = counts[2], moved = counts[3];
  EXPECT_EQ(persistent + removed + moved, 20);
  EXPECT_EQ(added, 2);
  EXPECT_EQ(second.size(), static_cast<std::size_t>(persistent + moved + added));
  for (const ObjectChange& change : changes) {
    if (change.state == ChangeState::kMoved) {
      EXPECT_GE((change.after - change.before).norm(), 2.0);
      EXPECT_LE((change.after - change.before).norm(), 6.0);
    }
  }
  std::vector<ObjectChange> again;
  const std::vector<WorldObject> repeat = ChangeObjects(first, ChangeSpec{}, 77, &again);
  ASSERT_EQ(repeat.size(), second.size());
  for (std::size_t i = 0; i < repeat.size(); ++i) EXPECT_EQ(repeat[i].centre, second[i].centre);
}

TEST(Detector, SeesAnObjectInFrontAndNotOneBehindAWall) {
  Scene scene;
  scene.textures.push_back(MakeFacadeTexture(10.0, 8.0, 1));
  scene.walls.push_back({Eigen::Vector2d(-5.0, -8.0), Eigen::Vector2d(5.0, -8.0), 8.0, 0});  // behind the camera's back
  WorldObject crate;
  crate.id = 7;
  crate.centre = Eigen::Vector2d(1.0, 6.0);
  const CameraIntrinsics camera{458.0, 458.0, 375.5, 239.5, 752, 480};
  const CameraPose looking_north{Eigen::Vector3d(0.0, 0.0, 3.0), M_PI / 2};
  DetectorOptions options;
  options.miss_rate = 0.0;
  options.false_rate = 0.0;
  options.centroid_sigma_m = 0.0;
  std::vector<Detection> found = DetectObjects({crate}, scene, camera, looking_north, options, 1);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].truth_id, 7);
  EXPECT_EQ(found[0].label, ObjectLabel::kCrate);
  EXPECT_NEAR(found[0].centroid.z(), 6.0, 1e-9);  // depth
  EXPECT_NEAR(found[0].centroid.x(), 1.0, 1e-9);  // right of the axis
  EXPECT_NEAR(found[0].centroid.y(), 2.5, 1e-9);  // 2.5 m below the camera
  EXPECT_NEAR(found[0].box.x + found[0].box.width / 2, 375.5 + 458.0 / 6.0, 12.0);
  const CameraPose looking_south{Eigen::Vector3d(0.0, 0.0, 3.0), -M_PI / 2};
  EXPECT_TRUE(DetectObjects({crate}, scene, camera, looking_south, options, 1).empty());   // behind the camera
  scene.walls.push_back({Eigen::Vector2d(-5.0, 3.0), Eigen::Vector2d(5.0, 3.0), 8.0, 0});  // a building in between
  EXPECT_TRUE(DetectObjects({crate}, scene, camera, looking_north, options, 1).empty());
}

TEST(Renderer, DepthImageHoldsWallGroundAndSkyDepths) {
  Scene scene;
  scene.textures.push_back(MakeFacadeTexture(40.0, 5.0, 1));
  scene.walls.push_back({Eigen::Vector2d(-20.0, 10.0), Eigen::Vector2d(20.0, 10.0), 5.0, 0});
  const CameraIntrinsics camera{458.0, 458.0, 375.5, 239.5, 752, 480};
  Renderer renderer(&scene, camera);
  cv::Mat depth;
  renderer.RenderDepth({Eigen::Vector3d(0.0, 0.0, 3.0), M_PI / 2}, &depth);
  EXPECT_EQ(depth.at<std::uint16_t>(240, 376), 10000);                        // the wall, 10 m away
  const int ground_row = static_cast<int>(std::lround(239.5 + 458.0 * 0.5));  // 3 m down at 6 m
  EXPECT_NEAR(depth.at<std::uint16_t>(ground_row, 376), 6000, 15);
  EXPECT_EQ(depth.at<std::uint16_t>(0, 376), 0);  // sky above the 5 m wall
}

TEST(EurocWriter, SameOptionsGiveTheSameLogByteForByte) {
  testing::TempDir dir;
  for (const char* name : {"a", "b"}) {
    SimulatedFlight flight;
    Village village = MakeVillage({2});
    flight.scene = std::move(village.scene);
    flight.camera = flight.camera.Scaled(0.25);
    flight.lighting = DrawLighting(2, 1);
    flight.objects = PlaceObjects(6, 2);
    AddObjects(flight.objects, &flight.scene);
    Route route{"short", {Eigen::Vector2d(-6, -6), Eigen::Vector2d(4, -6)}};
    ASSERT_TRUE(FlyRoute(route, RouteOptions{}, &flight).ok());
    LogOptions options;
    options.detections = options.depth = options.gps = true;
    ASSERT_TRUE(WriteEurocLog(flight, dir / name, options).ok());
  }
  int files = 0;
  for (const auto& item : std::filesystem::recursive_directory_iterator(dir / "a")) {
    if (!item.is_regular_file()) continue;
    const std::string relative = std::filesystem::relative(item.path(), dir / "a").string();
    EXPECT_EQ(testing::ReadText(item.path().string()), testing::ReadText(dir / ("b/" + relative))) << relative;
    ++files;
  }
  EXPECT_GT(files, 100);
}

}  // namespace
}  // namespace patrolmap::sim

namespace patrolmap::sim {
namespace {

// Mean absolute horizontal gradient and mean grey of the middle frame of a written log.
std::pair<double, double> MiddleFrameStatistics(const std::string& log) {
  std::vector<std::string> names;
  for (const auto& item : std::filesystem::directory_iterator(log + "/cam0/data")) names.push_back(item.path());
  std::sort(names.begin(), names.end());
  const cv::Mat image = cv::imread(names[names.size() / 2], cv::IMREAD_GRAYSCALE);
  cv::Mat gradient;
  cv::Sobel(image, gradient, CV_32F, 1, 0);
  return {cv::mean(cv::abs(gradient))[0], cv::mean(image)[0]};
}

TEST(EurocWriter, MotionBlurSmearsAlongTheMotion) {
  testing::TempDir dir;
  std::pair<double, double> statistics[2];
  for (int blurred = 0; blurred < 2; ++blurred) {
    StreetOptions street;
    street.walls = 2;
    street.speed_mps = 8.0;
    SimulatedFlight flight = MakeStreetFlight(street);
    flight.camera = flight.camera.Scaled(0.5);
    LogOptions options;
    options.exposure_s = blurred ? 0.03 : 0.0;  // 24 cm of travel: ~11 px at 5 m
    const std::string log = dir / (blurred ? "blurred" : "sharp");
    ASSERT_TRUE(WriteEurocLog(flight, log, options).ok());
    statistics[blurred] = MiddleFrameStatistics(log);
  }
  EXPECT_LT(statistics[1].first, 0.7 * statistics[0].first);     // much less horizontal detail
  EXPECT_NEAR(statistics[1].second, statistics[0].second, 2.0);  // same brightness
}

}  // namespace
}  // namespace patrolmap::sim
