// Tests of src/io/bag_messages.cc: ROS 1 and CDR wire bytes of the message types a flight log needs.
#include "bag_messages.h"

#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/wire_writer.h"

namespace patrolmap::io::rosmsg {
namespace {

std::vector<std::uint8_t> ImuBytes(Wire wire) {
  WireWriter writer(wire);
  writer.Header(12, 500, "imu0").Doubles({0, 0, 0, 1}).Doubles({-1, 0, 0, 0, 0, 0, 0, 0, 0});
  writer.Doubles({0.1, -0.2, 0.3}).Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0});
  writer.Doubles({0.0, 0.5, 9.81}).Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0});
  return writer.bytes();
}

// A 3x2 mono8 image with a step of 4 (one padding byte a row).
std::vector<std::uint8_t> ImageBytes(Wire wire, const std::string& encoding = "mono8") {
  WireWriter writer(wire);
  writer.Header(1, 2, "cam0").Put<std::uint32_t>(2).Put<std::uint32_t>(3).String(encoding);
  writer.Put<std::uint8_t>(0).Put<std::uint32_t>(4).Put<std::uint32_t>(8);
  for (std::uint8_t v : {1, 2, 3, 0, 4, 5, 6, 0}) writer.Put(v);
  return writer.bytes();
}

class Wires : public ::testing::TestWithParam<Wire> {};

TEST_P(Wires, ImuReadsGyroAccelAndStamp) {
  ImuMessage imu;
  ASSERT_TRUE(DecodeImu(ImuBytes(GetParam()), GetParam(), &imu).ok());
  EXPECT_EQ(imu.header.stamp_ns, 12'000'000'500);
  EXPECT_EQ(imu.header.frame_id, "imu0");
  EXPECT_EQ(imu.gyro, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(imu.accel, Eigen::Vector3d(0.0, 0.5, 9.81));
}

TEST_P(Wires, ImageKeepsItsLayout) {
  const std::vector<std::uint8_t> bytes = ImageBytes(GetParam());
  ImageMessage image;
  ASSERT_TRUE(DecodeImage(bytes, GetParam(), false, &image).ok());
  EXPECT_EQ(image.width, 3u);
  EXPECT_EQ(image.height, 2u);
  EXPECT_EQ(image.step, 4u);
  EXPECT_EQ(image.encoding, "mono8");
  ASSERT_EQ(image.size, 8u);
  EXPECT_EQ(image.data[4], 4);
  EXPECT_EQ(image.header.stamp_ns, 1'000'000'002);
}

TEST_P(Wires, EveryTruncationIsRefusedNotRead) {
  // Each prefix of a valid message fails with a message, never reads past its end (the sanitizer run).
  const std::vector<std::uint8_t> full = ImuBytes(GetParam());
  for (std::size_t size = 0; size < full.size(); ++size) {
    const std::vector<std::uint8_t> cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(size));
    ImuMessage imu;
    const Status status = DecodeImu(cut, GetParam(), &imu);
    EXPECT_EQ(status.code(), StatusCode::kDataLoss) << size;
  }
}

TEST_P(Wires, AnotherTypesBytesAreNotAnImage) {
  ImageMessage image;
  const Status status = DecodeImage(ImuBytes(GetParam()), GetParam(), false, &image);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
}

TEST_P(Wires, OdometryGivesPoseChildFrameAndVelocity) {
  WireWriter writer(GetParam());
  writer.Header(3, 0, "world")
      .String("body")
      .Doubles({1, 2, 3})
      .Doubles({0, 0, 0.7071067811865476, 0.7071067811865476});
  std::vector<double> covariance(36, 0.0);
  for (double c : covariance) writer.Put(c);
  writer.Doubles({3, 4, 0}).Doubles({0, 0, 0});
  for (double c : covariance) writer.Put(c);
  PoseMessage pose;
  ASSERT_TRUE(DecodePose(writer.bytes(), GetParam(), MessageKind::kOdometry, &pose).ok());
  EXPECT_EQ(pose.child_frame, "body");
  EXPECT_EQ(pose.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(pose.rotation.w(), 0.7071067811865476, 1e-12);
  EXPECT_NEAR(pose.rotation.z(), 0.7071067811865476, 1e-12);
  ASSERT_TRUE(pose.has_velocity);
  EXPECT_DOUBLE_EQ(pose.velocity.norm(), 5.0);
}

TEST_P(Wires, ZeroQuaternionIsNoRotation) {
  WireWriter writer(GetParam());
  writer.Header(3, 0, "world").Doubles({1, 2, 3}).Doubles({0, 0, 0, 0});
  PoseMessage pose;
  const Status status = DecodePose(writer.bytes(), GetParam(), MessageKind::kPoseStamped, &pose);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("not a rotation"), std::string::npos) << status.message();
}

TEST_P(Wires, TransformsAndCameraInfo) {
  WireWriter transforms(GetParam());
  transforms.Put<std::uint32_t>(1).Header(0, 0, "body").String("cam0").Doubles({0.1, 0, 0}).Doubles({0, 0, 0, 1});
  std::vector<TransformMessage> decoded;
  ASSERT_TRUE(DecodeTransforms(transforms.bytes(), GetParam(), &decoded).ok());
  ASSERT_EQ(decoded.size(), 1u);
  EXPECT_EQ(decoded[0].header.frame_id, "body");
  EXPECT_EQ(decoded[0].child_frame, "cam0");
  WireWriter info(GetParam());
  info.Header(0, 0, "cam0").Put<std::uint32_t>(480).Put<std::uint32_t>(752).String("plumb_bob");
  info.Put<std::uint32_t>(2).Doubles({-0.28, 0.07});
  info.Doubles({458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1}).Doubles({1, 0, 0, 0, 1, 0, 0, 0, 1});
  info.Doubles({458.654, 0, 367.215, 0, 0, 457.296, 248.375, 0, 0, 0, 1, 0});
  CameraInfoMessage camera;
  ASSERT_TRUE(DecodeCameraInfo(info.bytes(), GetParam(), &camera).ok());
  EXPECT_EQ(camera.width, 752u);
  EXPECT_EQ(camera.height, 480u);
  EXPECT_EQ(camera.distortion.size(), 2u);
  EXPECT_DOUBLE_EQ(camera.k[2], 367.215);
}

TEST_P(Wires, ASequenceLongerThanTheMessageIsRefused) {
  WireWriter writer(GetParam());
  writer.Put<std::uint32_t>(0x7fffffff);
  std::vector<TransformMessage> decoded;
  const Status status = DecodeTransforms(writer.bytes(), GetParam(), &decoded);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_TRUE(decoded.empty());
}

INSTANTIATE_TEST_SUITE_P(RosAndCdr, Wires, ::testing::Values(Wire::kRos1, Wire::kCdr));

TEST(Cdr, BigEndianIsNamed) {
  std::vector<std::uint8_t> bytes = ImuBytes(Wire::kCdr);
  bytes[1] = 0;
  ImuMessage imu;
  const Status status = DecodeImu(bytes, Wire::kCdr, &imu);
  EXPECT_NE(status.message().find("not little-endian CDR"), std::string::npos) << status.message();
}

TEST(Types, Ros1AndRos2NamesAreOneKind) {
  EXPECT_EQ(KindOfType("sensor_msgs/Image"), MessageKind::kImage);
  EXPECT_EQ(KindOfType("sensor_msgs/msg/Image"), MessageKind::kImage);
  EXPECT_EQ(KindOfType("nav_msgs/msg/Odometry"), MessageKind::kOdometry);
  EXPECT_EQ(KindOfType("std_msgs/String"), MessageKind::kOther);
}

}  // namespace
}  // namespace patrolmap::io::rosmsg
