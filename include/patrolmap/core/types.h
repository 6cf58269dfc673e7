// Plain value types that stages exchange (DESIGN.md, "Stages talk through plain
// value types"). Times are nanoseconds since an arbitrary epoch of the log;
// image coordinates are pixels with the origin at the top-left pixel centre.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace patrolmap {

using TimestampNs = std::int64_t;

// Timestamps patrolmap accepts lie in [0, kMaxTimestampNs] (2^62 ns: about 146 years after the epoch), so
// the difference of any two never overflows. Readers refuse others, naming the file and line.
constexpr TimestampNs kMaxTimestampNs = TimestampNs{1} << 62;
inline bool ValidTimestamp(TimestampNs ns) { return ns >= 0 && ns <= kMaxTimestampNs; }

inline double NsToSeconds(TimestampNs ns) { return static_cast<double>(ns) * 1e-9; }
inline TimestampNs SecondsToNs(double seconds) {
  return static_cast<TimestampNs>(seconds * 1e9 + (seconds >= 0 ? 0.5 : -0.5));
}

// One inertial measurement in the IMU frame: angular rate [rad/s], specific force [m/s^2].
struct ImuSample {
  TimestampNs timestamp_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

// Pinhole intrinsics at the log's native resolution [pixels].
struct CameraIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;
  bool valid() const { return fx > 0.0 && fy > 0.0 && width > 0 && height > 0; }
  // The same camera seen through an image resized by `scale`.
  CameraIntrinsics Scaled(double scale) const;
};

// Where the camera was: world_from_camera = (rotation, position).
struct CameraPoseSample {
  TimestampNs timestamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d ToWorld(const Eigen::Vector3d& in_camera) const { return rotation * in_camera + position; }
  Eigen::Vector3d ToCamera(const Eigen::Vector3d& in_world) const {
    return rotation.conjugate() * (in_world - position);
  }
};

// One object detection of one frame (objects0/data.csv).
struct ObjectObservation {
  TimestampNs timestamp_ns = 0;
  std::string label;
  double confidence = 0.0;
  cv::Rect2d box;                                  // in the image [pixels]
  std::optional<Eigen::Vector3d> centroid_camera;  // 3D centroid in the camera frame, when the detector gives one
};

// The radial-tangential lens distortion of a camera's raw images (k1, k2, p1, p2: OpenCV's and EuRoC's model);
// all zero for a pinhole camera.
using Distortion = std::array<double, 4>;

// Coefficients beyond this are no lens's of that model (EuRoC's k1 is -0.28; fisheye lenses have a model of their
// own): readers refuse them, and a map file holding one is corrupt.
inline constexpr double kMaxDistortionCoefficient = 10.0;
inline bool PlausibleDistortion(const Distortion& d) {
  for (const double k : d) {
    if (!(std::abs(k) <= kMaxDistortionCoefficient)) return false;  // NaN fails too
  }
  return true;
}

// Where a normalized image point (x/z, y/z) lands through the lens: k1, k2 bend it radially, p1, p2 tangentially.
// Beyond the radius where the radial term stops growing (r^2 with 1 + 3 k1 r^2 + 5 k2 r^4 <= 0) the polynomial
// folds back towards the centre; `folded` (when given) then says so, and the point is returned undistorted (it lies
// off any image the lens makes).
Eigen::Vector2d Distorted(const Distortion& d, const Eigen::Vector2d& point, bool* folded = nullptr);

// A calibrated stereo pair (EuRoC cam0 and cam1 with their sensor.yaml): the intrinsics and the
// distortion of each camera, and where the right camera sits in the left
// one's frame: x_right = right_from_left_rotation * x_left + right_from_left_translation [m].
struct StereoCalibration {
  CameraIntrinsics left, right;
  Distortion left_distortion{}, right_distortion{};
  Eigen::Matrix3d right_from_left_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d right_from_left_translation = Eigen::Vector3d::Zero();
};

// Depth of the log at one time: a depth image (depth0/), or the two images of a stereo pair (cam0/ and cam1/)
// that the depth stage matches. Files are read when the change stage wants them; a log that holds its images
// in its own file (a ROS bag) hands them over decoded.
struct DepthSample {
  TimestampNs timestamp_ns = 0;
  std::string path;                      // the depth image; for a stereo pair the left (cam0) image
  std::string right_path;                // the right (cam1) image of a stereo pair; empty for a depth image
  cv::Mat image;                         // instead of `path`: depth [m] (CV_32FC1, 0 = no return), or the left image
  cv::Mat right_image;                   // instead of `right_path`: the right image (CV_8UC1)
  std::optional<CameraPoseSample> pose;  // the camera pose at its time, when the log has poses
  bool stereo() const { return !right_path.empty() || !right_image.empty(); }
};

// One camera frame with the sensor data that arrived since the previous frame
// the source returned (so skipping frames never loses IMU samples, poses or depth images).
// Samples after the log's last frame come with it.
struct Frame {
  TimestampNs timestamp_ns = 0;
  std::int64_t index = 0;              // position in the log, counting unreadable frames too
  cv::Mat image;                       // CV_8UC1; empty when the caller asked not to decode
  cv::Mat colour;                      // CV_8UC3 BGR when the caller asked (FrameSource::KeepColour) and the
                                       // image is colour (image folders, EuRoC, videos); else empty
  std::vector<ImuSample> imu;          // samples with previous timestamp < t <= timestamp_ns
  std::optional<double> speed_mps;     // known platform speed, when the log carries it
  std::optional<Eigen::Vector3d> gps;  // latitude, longitude [deg], altitude [m], when the log carries it
  // What change detection reads, when the log has it (EuRoC: state_groundtruth_estimate0/, objects0/, depth0/):
  std::vector<CameraPoseSample> poses;        // state estimates with previous timestamp < t <= timestamp_ns
  std::optional<CameraPoseSample> pose;       // the camera pose at timestamp_ns (interpolated)
  std::vector<ObjectObservation> detections;  // at timestamp_ns exactly (a frame with some is always decoded)
  std::vector<DepthSample> depth;             // depth images with previous timestamp < t <= timestamp_ns
};

// Kind of extremum of the smoothed scene-flow response (paper 002 §III-A).
enum class ExtremumKind { kPeak, kValley };

// One processed frame of the flow stage: the response signal before and after smoothing.
struct FlowSample {
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  double raw_response = 0.0;       // NaN when no flow vector was accepted
  double smoothed_response = 0.0;  // NaN until the smoothing window holds a valid sample
  int tracked_vectors = 0;
  int accepted_vectors = 0;
};

// A key location event: an extremum of the smoothed response (a node of the map).
struct KeyLocation {
  int node_index = 0;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  double response = 0.0;  // smoothed response at the extremum
  ExtremumKind kind = ExtremumKind::kPeak;
};

const char* ToString(ExtremumKind kind);

// The 8 corners of a box standing on z = 0 at `centre`, turned by `yaw` about the vertical, `length` along
// the yaw direction and `width` across it.
std::array<Eigen::Vector3d, 8> StandingBoxCorners(const Eigen::Vector2d& centre, double yaw, double length,
                                                  double width, double height);

}  // namespace patrolmap
