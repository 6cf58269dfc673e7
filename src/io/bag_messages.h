// Internal: the ROS message types a flight log needs, decoded from their wire bytes. One decoder serves
// both wire formats: ROS 1 serialisation (little-endian, packed, strings without a terminator, a header
// with a sequence number) and ROS 2's CDR (an encapsulation header, primitives aligned to their size,
// strings with a terminator, a header without a sequence number). Debian ships the ROS 1 message headers
// but nothing that reads CDR, so both are read here, field by field, with every length checked.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io::rosmsg {

enum class Wire { kRos1, kCdr };

// The message types patrolmap reads; kOther for any other type (listed, not decoded).
enum class MessageKind {
  kImage,
  kCompressedImage,
  kImu,
  kNavSatFix,
  kPoseStamped,
  kPoseWithCovarianceStamped,
  kOdometry,
  kCameraInfo,
  kTransforms,
  kOther
};

// "sensor_msgs/Image" (ROS 1) or "sensor_msgs/msg/Image" (ROS 2).
MessageKind KindOfType(const std::string& type);

struct Header {
  TimestampNs stamp_ns = 0;  // 0 when the sender left it empty
  std::string frame_id;
};

// sensor_msgs/Image, or the bytes of a CompressedImage (format, data).
struct ImageMessage {
  Header header;
  bool compressed = false;
  std::string encoding;  // Image: "mono8", "bgr8", ...; CompressedImage: its format ("jpeg", "png", ...)
  std::uint32_t width = 0, height = 0, step = 0;
  bool big_endian = false;
  const std::uint8_t* data = nullptr;  // into the message's bytes
  std::size_t size = 0;
};

struct ImuMessage {
  Header header;
  // The attitude (world from IMU frame), when the sender gives one: ROS marks "none" with a first
  // orientation covariance of -1, and an all-zero quaternion is none too.
  std::optional<Eigen::Quaterniond> orientation;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

struct NavSatFixMessage {
  Header header;
  int status = 0;                                      // < 0: no fix
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // latitude, longitude [deg], altitude [m]
};

// PoseStamped, PoseWithCovarianceStamped or Odometry: where `child_frame` is in header.frame_id's frame.
struct PoseMessage {
  Header header;
  std::string child_frame;  // Odometry's child_frame_id; empty for the others
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  bool has_velocity = false;  // Odometry: twist.linear, in the child frame
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

struct CameraInfoMessage {
  Header header;
  std::uint32_t width = 0, height = 0;
  std::string distortion_model;
  std::vector<double> distortion;
  std::array<double, 9> k{};
  std::array<double, 9> r{};
  std::array<double, 12> p{};
};

struct TransformMessage {
  Header header;  // the parent frame
  std::string child_frame;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// Each fails with DataLoss ("message ends inside FIELD", "… is not a number") on bytes that do not hold
// the type. An image's data points into `bytes`, which must outlive it.
Status DecodeImage(const std::vector<std::uint8_t>& bytes, Wire wire, bool compressed, ImageMessage* message);
Status DecodeImu(const std::vector<std::uint8_t>& bytes, Wire wire, ImuMessage* message);
Status DecodeNavSatFix(const std::vector<std::uint8_t>& bytes, Wire wire, NavSatFixMessage* message);
Status DecodePose(const std::vector<std::uint8_t>& bytes, Wire wire, MessageKind kind, PoseMessage* message);
Status DecodeCameraInfo(const std::vector<std::uint8_t>& bytes, Wire wire, CameraInfoMessage* message);
Status DecodeTransforms(const std::vector<std::uint8_t>& bytes, Wire wire, std::vector<TransformMessage>* transforms);

}  // namespace patrolmap::io::rosmsg
