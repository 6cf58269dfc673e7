#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "io/fixtures.h"
#include "log_capture.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/io/natural_sort.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/io/yaml_file.h"
#include "test_util.h"

namespace patrolmap::io {
namespace {

using testing::LogCapture;
using testing::TempDir;
using testing::WriteText;
using testing_fixtures::MakeEurocLog;
using testing_fixtures::TestImage;

TEST(PatrolSensors, PosesDetectionsAndDepthOfALog) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  // A camera looking along body +x: T_BS maps camera axes to body axes x_c -> -y_b, y_c -> -z_b, z_c -> +x_b.
  WriteText(log + "/cam0/sensor.yaml",
            "T_BS:\n  cols: 4\n  rows: 4\n  data: [0, 0, 1, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 1]\n"
            "rate_hz: 20\nresolution: [32, 24]\nintrinsics: [20, 20, 15.5, 11.5]\n");
  // Body yawed by 90 degrees (facing +y) at the first row, moving 1 m along +y by the second.
  const double h = std::sqrt(0.5);
  WriteText(log + "/state_groundtruth_estimate0/data.csv",
            "1000000000,0,0,2," + std::to_string(h) + ",0,0," + std::to_string(h) + ",0,0,0\n" + "1100000000,0,1,2," +
                std::to_string(h) + ",0,0," + std::to_string(h) + ",0,0,0\n");
  WriteText(log + "/objects0/data.csv",
            "#t,label,confidence,x0,y0,x1,y1,x,y,z\n1000000000,crate,0.8,1,2,11,12,0.5,0.25,6\n"
            "1000000000,barrel,0.6,20,2,25,9\n1050000000,crate,0.7,2,2,12,12,0.5,0.25,5.5\n");
  std::filesystem::create_directories(log + "/depth0/data");
  cv::imwrite(log + "/depth0/data/d.png", cv::Mat(24, 32, CV_16UC1, cv::Scalar(4500)));
  WriteText(log + "/depth0/data.csv", "#t,filename\n1000000000,d.png\n");
  PatrolSensors sensors;
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  ASSERT_EQ(sensors.poses.size(), 2u);
  // The camera axis (z) points along world +y; a point 6 m ahead lies at (0, 6, 2).
  const Eigen::Vector3d ahead = sensors.poses[0].ToWorld(Eigen::Vector3d(0, 0, 6));
  EXPECT_LT((ahead - Eigen::Vector3d(0, 6, 2)).norm(), 1e-9);
  const Eigen::Vector3d right = sensors.poses[0].ToWorld(Eigen::Vector3d(1, 0, 0)) - sensors.poses[0].position;
  EXPECT_LT((right - Eigen::Vector3d(1, 0, 0)).norm(), 1e-9);  // facing +y, the camera's right is +x
  const std::optional<CameraPoseSample> halfway = PoseAt(sensors.poses, 1050000000);
  ASSERT_TRUE(halfway.has_value());
  EXPECT_NEAR(halfway->position.y(), 0.5, 1e-12);
  EXPECT_FALSE(PoseAt(sensors.poses, 1200000000).has_value());
  EXPECT_FALSE(PoseAt(sensors.poses, 1050000000, 50000000).has_value());  // a gap longer than allowed
  ASSERT_EQ(sensors.detections.size(), 3u);
  EXPECT_EQ(sensors.detections[1].label, "barrel");
  EXPECT_FALSE(sensors.detections[1].centroid_camera.has_value());
  EXPECT_DOUBLE_EQ(sensors.detections[0].centroid_camera->z(), 6.0);
  EXPECT_DOUBLE_EQ(sensors.detections[0].box.width, 10.0);
  ASSERT_EQ(sensors.depth.size(), 1u);
  cv::Mat depth;
  ASSERT_TRUE(ReadDepthImage(sensors.depth[0].path, &depth).ok());
  EXPECT_FLOAT_EQ(depth.at<float>(3, 4), 4.5f);
  ASSERT_TRUE(sensors.camera.has_value());
  EXPECT_EQ(sensors.camera->width, 32);
  // Depth images the table lists but the log lacks are dropped with one warning naming the first.
  WriteText(log + "/depth0/data.csv", "#t,filename\n1000000000,d.png\n1100000000,gone.png\n1200000000,6\n");
  LogCapture capture;
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  EXPECT_EQ(sensors.depth.size(), 1u);
  EXPECT_NE(capture.text().find("depth0/data.csv: 2 of the 3 depth images it lists are missing (the first: " + log +
                                "/depth0/data/gone.png); they are skipped"),
            std::string::npos)
      << capture.text();
}

// The EuRoC reader hands each frame the samples that belong to it: the poses and depth images since the
// previous frame (those after the last frame with the last), the pose at its time, and the detections at
// exactly its time (it then decodes the image even when not asked: the object map needs it).
TEST(PatrolSensors, TheirSamplesComeWithTheFrames) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);  // frames at 1.00, 1.05 and 1.10 s
  WriteText(log + "/cam0/sensor.yaml", "rate_hz: 20\nresolution: [32, 24]\nintrinsics: [20, 20, 15.5, 11.5]\n");
  WriteText(log + "/state_groundtruth_estimate0/data.csv",
            "1000000000,0,0,2,1,0,0,0,0,0,0\n1100000000,0,1,2,1,0,0,0,0,0,0\n1200000000,0,2,2,1,0,0,0,0,0,0\n");
  WriteText(log + "/objects0/data.csv",
            "1000000000,crate,0.8,1,2,11,12\n1000000000,barrel,0.6,20,2,25,9\n1020000000,crate,0.7,2,2,12,12\n"
            "1050000000,crate,0.7,2,2,12,12\n");
  std::filesystem::create_directories(log + "/depth0/data");
  cv::imwrite(log + "/depth0/data/d.png", cv::Mat(24, 32, CV_16UC1, cv::Scalar(4500)));
  WriteText(log + "/depth0/data.csv", "1000000000,d.png\n1080000000,d.png\n1150000000,d.png\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_TRUE(source->info().has_poses && source->info().has_detections && source->info().has_depth);
  Frame frame;
  ASSERT_TRUE(source->Next(false, &frame).ok());  // 1.00 s
  EXPECT_EQ(frame.poses.size(), 1u);
  ASSERT_TRUE(frame.pose.has_value());
  EXPECT_EQ(frame.detections.size(), 2u);
  ASSERT_EQ(frame.depth.size(), 1u);
  EXPECT_TRUE(frame.depth[0].pose.has_value());
  EXPECT_FALSE(frame.image.empty());
  ASSERT_TRUE(source->Next(false, &frame).ok());  // 1.05 s: the detection at 1.02 s belonged to no frame
  EXPECT_TRUE(frame.poses.empty());
  ASSERT_TRUE(frame.pose.has_value());
  EXPECT_NEAR(frame.pose->position.y(), 0.5, 1e-12);
  EXPECT_EQ(frame.detections.size(), 1u);
  EXPECT_TRUE(frame.depth.empty());
  EXPECT_FALSE(frame.image.empty());
  ASSERT_TRUE(source->Next(false, &frame).ok());  // 1.10 s, the last: the pose and depth after it too
  EXPECT_EQ(frame.poses.size(), 2u);
  EXPECT_TRUE(frame.detections.empty());
  ASSERT_EQ(frame.depth.size(), 2u);
  EXPECT_EQ(frame.depth[1].timestamp_ns, 1150000000);
  EXPECT_TRUE(frame.image.empty());
  EXPECT_TRUE(source->Next(false, &frame).end_of_stream());
}

TEST(PatrolSensors, BadTablesNameFileAndLine) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 2);
  PatrolSensors sensors;
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,1,2,11,12\n1000000000,crate,1.7,1,2,11,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("objects0/data.csv:2: confidence must lie in [0, 1]"),
            std::string::npos);
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,11,2,1,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("x_max > x_min"), std::string::npos);
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,1,2,11,12\n900000000,crate,0.8,1,2,11,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("objects0/data.csv:2: timestamp 900000000 is before"),
            std::string::npos);
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,1,2,11,12,0.5,0.2\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("objects0/data.csv:1: a centroid needs three values"),
            std::string::npos);
  std::filesystem::remove(log + "/objects0/data.csv");
  WriteText(log + "/state_groundtruth_estimate0/data.csv", "1000000000,0,0,2,0.5,0,0,0,0,0,0\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("q_RS is not a unit quaternion"), std::string::npos);
  std::filesystem::remove(log + "/state_groundtruth_estimate0/data.csv");
  std::filesystem::create_directories(log + "/depth0/data");
  cv::imwrite(log + "/depth0/data/d.png", TestImage(9));
  WriteText(log + "/depth0/data.csv", "1000000000,d.png\n");
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  cv::Mat depth;
  EXPECT_NE(ReadDepthImage(sensors.depth[0].path, &depth).message().find("d.png: depth image must be 16-bit"),
            std::string::npos);
  EXPECT_EQ(ReadDepthImage(dir / "none.png", &depth).code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace patrolmap::io
