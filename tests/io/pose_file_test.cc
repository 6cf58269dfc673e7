// Pose files (--poses): TUM and KITTI lines, their errors, and a log that takes its camera poses from one.
#include "patrolmap/io/pose_file.h"

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "io/fixtures.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/io/readers.h"
#include "test_util.h"

namespace patrolmap::io {
namespace {

using testing::TempDir;
using testing::WriteText;

TEST(PoseFile, TumLinesAreTimedCameraPoses) {
  TempDir dir;
  WriteText(dir / "poses.txt",
            "# timestamp tx ty tz qx qy qz qw\n1.5 1 2 3 0 0 0 1\n\n2.0 4 5 6 0 0 0.7071068 0.7071068\n");
  std::vector<CameraPoseSample> poses;
  ASSERT_TRUE(ReadPoseFile(dir / "poses.txt", {}, &poses).ok());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].timestamp_ns, 1'500'000'000);
  EXPECT_EQ(poses[1].position, Eigen::Vector3d(4, 5, 6));
  // A quarter turn about z: the camera's x axis points along the world's y.
  EXPECT_NEAR((poses[1].rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-6);
}

TEST(PoseFile, KittiLinesTakeTheTimesOfTheLogsImages) {
  TempDir dir;
  WriteText(dir / "poses.txt", "1 0 0 0.5 0 1 0 0 0 0 1 2\n0 -1 0 1 1 0 0 0 0 0 1 3\n");
  std::vector<CameraPoseSample> poses;
  ASSERT_TRUE(ReadPoseFile(dir / "poses.txt", {100, 200}, &poses).ok());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[1].timestamp_ns, 200);
  EXPECT_EQ(poses[0].position, Eigen::Vector3d(0.5, 0, 2));
  EXPECT_NEAR((poses[1].rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-9);
  const Status status = ReadPoseFile(dir / "poses.txt", {100, 200, 300}, &poses);
  EXPECT_NE(status.message().find("2 KITTI poses for the log's 3 images"), std::string::npos) << status.message();
}

TEST(PoseFile, BadLinesNameFileAndLine) {
  TempDir dir;
  const auto error = [&](const std::string& text, const std::vector<TimestampNs>& times = {1, 2}) {
    WriteText(dir / "poses.txt", text);
    std::vector<CameraPoseSample> poses;
    return ReadPoseFile(dir / "poses.txt", times, &poses).message();
  };
  EXPECT_NE(error("1 2 3\n").find("poses.txt:1: 3 values; a pose line has 8"), std::string::npos);
  EXPECT_NE(error("1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n").find("poses.txt:2: 7 values, the lines before have 8"),
            std::string::npos);
  EXPECT_NE(error("1 0 0 nan 0 0 0 1\n").find("poses.txt:1: 'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(error("1 0 0 0 0 0 0 2\n").find("not of unit length"), std::string::npos);
  EXPECT_NE(error("2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n").find("poses.txt:2: times must increase"), std::string::npos);
  EXPECT_NE(error("2 0 0 0 0 2 0 0 0 0 1 0\n").find("poses.txt:1: the 3x3 part of the matrix is not a rotation"),
            std::string::npos);
  EXPECT_NE(error("# nothing\n").find("no poses"), std::string::npos);
  std::vector<CameraPoseSample> poses;
  EXPECT_EQ(ReadPoseFile(dir / "missing.txt", {}, &poses).code(), StatusCode::kNotFound);
}

TEST(PoseFile, ALogTakesItsCameraPosesFromTheFile) {
  TempDir dir;
  const std::string log = dir / "flight";
  testing_fixtures::MakeEurocLog(log, 4);  // frames at 1.00, 1.05, 1.10, 1.15 s
  WriteText(dir / "poses.txt", "1.0 0 0 0 0 0 0 1\n1.2 2 0 0 0 0 0 1\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_FALSE(source->info().has_poses);
  ASSERT_TRUE(source->UsePoseFile(dir / "poses.txt").ok());
  EXPECT_TRUE(source->info().has_poses);
  EXPECT_EQ(source->info().pose_source, kPosesFromFile);
  Frame frame;
  ASSERT_TRUE(source->Next(false, &frame).ok());
  ASSERT_TRUE(source->Next(false, &frame).ok());
  ASSERT_TRUE(frame.pose.has_value());
  EXPECT_NEAR(frame.pose->position.x(), 0.5, 1e-9);  // interpolated at 1.05 s
}

TEST(PoseFile, AVideoRefusesAPoseFile) {
  TempDir dir;
  const std::string video = dir / "clip.avi";
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(32, 24), false);
  if (!writer.isOpened()) GTEST_SKIP() << "no MJPG writer";
  for (int i = 0; i < 3; ++i) writer.write(testing_fixtures::TestImage(10 * i));
  writer.release();
  WriteText(dir / "poses.txt", "1.0 0 0 0 0 0 0 1\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(video, {}, &source).ok());
  const Status status = source->UsePoseFile(dir / "poses.txt");
  EXPECT_NE(status.message().find("not a video"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace patrolmap::io
