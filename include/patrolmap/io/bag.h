// ROS bags as flight logs: ROS 1 `.bag` files (format 2.0, plain, bz2 or lz4 chunks) and ROS 2 bags (a
// folder with metadata.yaml and sqlite3 `.db3` files). A bag is read as one stream of frames in time
// order, each with the samples of the other topics that belong to it (readers.h, OpenLog).
//
// Topics, by default the first of each kind (or as chosen with TopicChoice):
//   camera       sensor_msgs/Image (mono8, mono16, bgr8, rgb8, bgra8, rgba8) or CompressedImage (JPEG, PNG)
//   camera_info  sensor_msgs/CameraInfo: the intrinsics (K) and the image size
//   imu          sensor_msgs/Imu: gyro and accelerometer
//   gps          sensor_msgs/NavSatFix: latitude, longitude, altitude (fixes with status < 0 are left out)
//   pose         geometry_msgs/PoseStamped, PoseWithCovarianceStamped or nav_msgs/Odometry: the platform's
//                pose in a world frame; with /tf_static turned into the camera's pose
//   /tf_static   tf2_msgs/TFMessage: the rotations between the camera, IMU and pose frames
// A frame's time is its header stamp; a message whose stamp is 0 is timed by when it was recorded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patrolmap/core/status.h"

namespace patrolmap::io {

struct BagTopic {
  std::string name;
  std::string type;        // as the bag names it: "sensor_msgs/Image" or "sensor_msgs/msg/Image"
  std::int64_t count = 0;  // messages
  double rate_hz = 0.0;    // median rate of its record times; 0 with fewer than two messages
};

// Whether `path` is a ROS bag: a file ending in .bag, a ROS 2 bag folder (with metadata.yaml), or a .db3
// file inside one.
bool IsBag(const std::string& path);

// Whether this build reads ROS 1 bags (rosbag_storage) and ROS 2 bags (sqlite3).
bool Ros1BagsSupported();
bool Ros2BagsSupported();

// The topics of a bag with their types, counts and rates.
Status ListBagTopics(const std::string& path, std::vector<BagTopic>* topics);

}  // namespace patrolmap::io
