// What change detection reads from a flight log besides the images: the
// camera poses (state estimate), object detections and depth images.
//
//   state_groundtruth_estimate0/data.csv  timestamp, p_RS_R xyz, q_RS wxyz, ...: body
//                                         poses; with cam0/sensor.yaml's T_BS rotation
//                                         they give the camera poses
//   objects0/data.csv                     timestamp, label, confidence, x_min, y_min,
//                                         x_max, y_max [px], and optionally the 3D centroid
//                                         x, y, z in the camera frame [m]; several rows
//                                         may share a timestamp
//   depth0/data.csv + depth0/data/        timestamp, file name: 16-bit PNGs, depth along
//                                         the optical axis [mm], 0 = no return
//   cam1/data.csv + cam1/sensor.yaml      the right camera of a stereo pair (intrinsics,
//                                         radial-tangential distortion, T_BS): its images of
//                                         cam0's times make stereo pairs for the depth stage
// Every part is optional; a log without poses gets appearance changes only.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/status.h"

namespace patrolmap::io {

struct DepthEntry {
  TimestampNs timestamp_ns = 0;
  std::string path;        // depth image; stereo: the left (cam0) image
  std::string right_path;  // stereo: the right (cam1) image
};

struct PatrolSensors {
  std::string flight_id;
  std::optional<CameraIntrinsics> camera;
  std::vector<CameraPoseSample> poses;        // world_from_camera, ascending time
  std::string pose_source;                    // kPosesFromStateEstimate or kPosesFromGps; empty without poses
  std::vector<ObjectObservation> detections;  // ascending time
  std::vector<DepthEntry> depth;              // ascending time
  std::vector<DepthEntry> stereo;             // cam0 and cam1 images of the same time (EuRoC reader), ascending
};

// Reads the optional tables of a log (EuRoC layout; other logs have none).
// Malformed rows fail with the file and line.
Status ReadPatrolSensors(const std::string& log, PatrolSensors* sensors);

// The same tables under `root` (the folder holding cam0/), with the camera's rotation in the body frame
// (EuRoC T_BS of cam0) turning body poses into camera poses. The EuRoC reader hands their samples out with
// the frames.
Status ReadSensorTables(const std::string& root, const Eigen::Matrix3d& body_from_camera, PatrolSensors* sensors);

// The camera pose at `timestamp_ns`, interpolated between the two nearest
// samples; nullopt when it lies outside the samples or in a gap longer than
// `max_gap_ns`.
std::optional<CameraPoseSample> PoseAt(const std::vector<CameraPoseSample>& poses, TimestampNs timestamp_ns,
                                       TimestampNs max_gap_ns = 500'000'000);

// Reads a depth image into metres (CV_32FC1, 0 = no return); fails naming the
// file when it is missing, unreadable or not 16-bit single-channel.
Status ReadDepthImage(const std::string& path, cv::Mat* depth_m);

}  // namespace patrolmap::io
