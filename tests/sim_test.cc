#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "patrolmap/io/readers.h"
#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/renderer.h"
#include "test_util.h"

namespace patrolmap::sim {
namespace {

const CameraIntrinsics kCamera{458.0, 458.0, 375.5, 239.5, 752, 480};

// One wall parallel to the x axis at y = distance, 40 m long, with a facade texture.
Scene WallScene(double distance, std::uint32_t seed) {
  Scene scene;
  scene.textures.push_back(MakeFacadeTexture(40.0, 12.0, seed));
  scene.walls.push_back({Eigen::Vector2d(-20.0, distance), Eigen::Vector2d(20.0, distance), 12.0, 0});
  return scene;
}

TEST(Projection, KnownWallPointLandsAtTheKnownPixel) {
  const CameraPose pose{Eigen::Vector3d(0.0, 0.0, 3.0), M_PI / 2};  // looking along +y
  Eigen::Vector2d pixel;
  ASSERT_TRUE(Project(kCamera, pose, Eigen::Vector3d(2.0, 10.0, 3.0), &pixel));
  EXPECT_NEAR(pixel.x(), 375.5 + 458.0 * 0.2, 1e-9);  // 2 m right at 10 m depth
  EXPECT_NEAR(pixel.y(), 239.5, 1e-9);
  ASSERT_TRUE(Project(kCamera, pose, Eigen::Vector3d(0.0, 10.0, 0.0), &pixel));
  EXPECT_NEAR(pixel.y(), 239.5 + 458.0 * 0.3, 1e-9);  // 3 m below the camera
  EXPECT_FALSE(Project(kCamera, pose, Eigen::Vector3d(0.0, -10.0, 3.0), &pixel));
}

TEST(Renderer, DepthOfAFrontoParallelWallIsItsDistance) {
  const Scene scene = WallScene(10.0, 1);
  Renderer renderer(&scene, kCamera);
  std::vector<double> depths;
  renderer.ColumnDepths({Eigen::Vector3d(0.0, 0.0, 3.0), M_PI / 2}, &depths);
  for (double depth : depths) EXPECT_NEAR(depth, 10.0, 1e-9);
  renderer.ColumnDepths({Eigen::Vector3d(0.0, 0.0, 3.0), -M_PI / 2}, &depths);  // facing away
  EXPECT_TRUE(std::isinf(depths[376]));
}

TEST(Renderer, WallTopAndGroundAppearWhereGeometrySaysSo) {
  Scene scene = WallScene(10.0, 1);
  scene.walls[0].height = 5.0;  // top 2 m above the camera: row 239.5 - 458 * 0.2 = 147.9
  scene.sky_grey = 255;
  Renderer renderer(&scene, kCamera);
  cv::Mat image;
  renderer.Render({Eigen::Vector3d(0.0, 0.0, 3.0), M_PI / 2}, &image);
  EXPECT_EQ(image.at<uchar>(140, 376), 255);  // sky above the top edge
  EXPECT_NE(image.at<uchar>(156, 376), 255);  // wall below it
}

TEST(Renderer, LateralMotionShiftsTheImageByFocalTimesBaselineOverDepth) {
  const Scene scene = WallScene(10.0, 2);
  Renderer renderer(&scene, kCamera);
  cv::Mat first, second;
  renderer.Render({Eigen::Vector3d(0.0, 0.0, 6.0), M_PI / 2}, &first);
  renderer.Render({Eigen::Vector3d(0.5, 0.0, 6.0), M_PI / 2}, &second);
  cv::Mat a, b;
  first(cv::Rect(100, 0, 552, 480)).convertTo(a, CV_64F);
  second(cv::Rect(100, 0, 552, 480)).convertTo(b, CV_64F);
  const cv::Point2d shift = cv::phaseCorrelate(a, b);
  EXPECT_NEAR(shift.x, -458.0 * 0.5 / 10.0, 0.3);  // the scene moves left as the camera moves right
  EXPECT_NEAR(shift.y, 0.0, 0.3);
}

TEST(Renderer, SameSeedSameImageOtherSeedOtherImage) {
  const Scene a = WallScene(8.0, 11), b = WallScene(8.0, 11), c = WallScene(8.0, 12);
  const CameraPose pose{Eigen::Vector3d(1.0, 0.0, 3.0), M_PI / 2};
  cv::Mat image_a, image_b, image_c;
  Renderer(&a, kCamera).Render(pose, &image_a);
  Renderer(&b, kCamera).Render(pose, &image_b);
  Renderer(&c, kCamera).Render(pose, &image_c);
  EXPECT_EQ(cv::norm(image_a, image_b, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(image_a, image_c, cv::NORM_L1), 1e5);
}

TEST(StreetTruth, EdgesCrossTheViewAxisWhenTheCameraPassesThem) {
  std::vector<Eigen::Vector2d> gaps;
  const SimulatedFlight flight = MakeStreetFlight(StreetOptions{}, &gaps);  // gaps [16, 28] and [44, 56] m
  ASSERT_EQ(gaps.size(), 2u);
  const std::vector<TruthKeyLocation> truth = KeyLocationTruth(flight);
  ASSERT_EQ(truth.size(), 4u);
  const double start = 8.0, speed = 2.5;
  const double edges[] = {gaps[0].x(), gaps[0].y(), gaps[1].x(), gaps[1].y()};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(NsToSeconds(truth[i].timestamp_ns), (edges[i] - start) / speed, 1.0 / 30.0 + 1e-9) << i;
    EXPECT_EQ(truth[i].opening, i % 2 == 0);
    EXPECT_NEAR(truth[i].depth_before, i % 2 == 0 ? 5.0 : 25.0, 0.2);
  }
}

TEST(EurocWriter, WrittenLogReadsBackWithSensorsAndSpeed) {
  testing::TempDir dir;
  StreetOptions options;
  options.walls = 2;
  options.speed_mps = 10.0;  // a short log
  const SimulatedFlight flight = MakeStreetFlight(options);
  ASSERT_TRUE(WriteEurocLog(flight, dir / "log").ok());
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(dir / "log", {}, &source).ok());
  const io::LogInfo& info = source->info();
  EXPECT_EQ(info.frame_count, FrameCount(flight));
  ASSERT_TRUE(info.camera && info.camera_from_imu);
  EXPECT_DOUBLE_EQ(info.camera->fx, 458.0);
  EXPECT_EQ(info.flight_id, "street");
  // Camera looks left: its optical axis (z) is the body's y axis.
  EXPECT_NEAR((*info.camera_from_imu)(2, 1), 1.0, 1e-9);
  Frame frame;
  ASSERT_TRUE(source->Next(true, &frame).ok());
  ASSERT_TRUE(source->Next(true, &frame).ok());
  EXPECT_EQ(frame.image.cols, 752);
  ASSERT_TRUE(frame.speed_mps.has_value());
  EXPECT_NEAR(*frame.speed_mps, 10.0, 1e-6);
  EXPECT_FALSE(frame.imu.empty());
  EXPECT_NEAR(frame.imu.back().accel.z(), 9.81, 1e-6);
}

// A camera slower than the flight's frame rate: every third frame, each the image the full rate has at that time.
TEST(EurocWriter, AFrameStepWritesEveryNthFrameOfTheFullRate) {
  testing::TempDir dir;
  StreetOptions options;
  options.walls = 2;
  options.speed_mps = 10.0;
  SimulatedFlight flight = MakeStreetFlight(options);
  flight.camera = {114.5, 114.5, 93.5, 59.5, 188, 120};  // small images: the test is about which frames
  LogOptions every_third;
  every_third.frame_step = 3;
  ASSERT_TRUE(WriteEurocLog(flight, dir / "full").ok());
  ASSERT_TRUE(WriteEurocLog(flight, dir / "third", every_third).ok());
  std::unique_ptr<io::FrameSource> full, third;
  ASSERT_TRUE(io::OpenLog(dir / "full", {}, &full).ok());
  ASSERT_TRUE(io::OpenLog(dir / "third", {}, &third).ok());
  EXPECT_EQ(third->info().frame_count, WrittenFrameCount(flight, every_third));
  EXPECT_EQ(third->info().frame_rate_hz, 10.0);
  Frame a, b;
  for (int i = 0; i < third->info().frame_count; ++i) {
    ASSERT_TRUE(third->Next(true, &b).ok());
    for (int skip = 0; skip < (i == 0 ? 1 : 3); ++skip) ASSERT_TRUE(full->Next(true, &a).ok());
    ASSERT_EQ(a.timestamp_ns, b.timestamp_ns) << "frame " << i;
    ASSERT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0) << "frame " << i;
  }
  EXPECT_FALSE(third->Next(true, &b).ok());
  LogOptions none;
  none.frame_step = 0;
  EXPECT_FALSE(WriteEurocLog(flight, dir / "none", none).ok());
}

}  // namespace
}  // namespace patrolmap::sim
