// FrameSource: one interface for every kind of flight log (DESIGN.md, io).
// Readers never decide algorithm parameters; they only deliver frames.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/flight_id.h"
#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

// A flight id as the map and its tables keep it (core/flight_id.h: CleanedFlightId); a warning names any change.
// HTML, XML and JSON writers escape the rest.
std::string CleanFlightId(const std::string& raw);

// What a reader knows about a log before reading frames.
struct LogInfo {
  std::string path;
  std::string kind;                        // "euroc", "image-folder", "image-pattern", "video"
  std::string flight_id;                   // from meta.yaml, else the folder name
  std::optional<CameraIntrinsics> camera;  // from cam0/sensor.yaml when present
  Distortion camera_distortion{};          // of cam0's lens (sensor.yaml, a bag's camera info); zero when unknown
  // Rotation taking IMU-frame vectors into the camera frame, when both
  // extrinsics are known (EuRoC T_BS of cam0 and imu0).
  std::optional<Eigen::Matrix3d> camera_from_imu;
  // Rotation taking camera-frame vectors into the body (state estimate) frame:
  // EuRoC T_BS of cam0, when cam0/sensor.yaml is present.
  std::optional<Eigen::Matrix3d> body_from_camera;
  std::int64_t frame_count = -1;  // -1 when unknown (live or some videos)
  double frame_rate_hz = 0.0;     // nominal; 0 when unknown
  // Whether frame times come from the log or the user (--fps); false when a rate was assumed, so
  // durations measured in frames are all the log can offer (place.exclude_recent_images).
  bool timed = true;
  std::string timing;  // where the times came from, for messages
  bool has_imu = false;
  bool has_speed = false;
  // Change detection's tables (EuRoC): their samples come with the frames (Frame::poses, detections, depth).
  bool has_poses = false;
  std::string pose_source;  // where they come from (kPosesFrom... of core/patrol_data.h); empty without
  bool has_detections = false;
  bool has_depth = false;   // depth0/ images
  bool has_stereo = false;  // stereo pairs (cam0 + cam1 with their calibration)
  std::optional<StereoCalibration> stereo;
};

// A frame that could not be read and was skipped.
struct SkippedFrame {
  std::int64_t index = 0;
  std::string reason;  // names the file and the problem
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Reads the next frame into `frame`. With `decode_image` false the image is
  // left empty (for frames the caller skips; much cheaper). Returns
  // Status::EndOfStream() after the last frame. An unreadable image in the
  // middle of a log is counted in skipped(), logged, and passed over: the call
  // returns the next readable frame instead.
  virtual Status Next(bool decode_image, Frame* frame) = 0;

  virtual const LogInfo& info() const = 0;

  // Names the flight `id` (a valid one, core/flight_id.h) instead of the id the log gave, before the first Next().
  virtual void SetFlightId(std::string id) = 0;

  // Takes the camera poses from a pose file (io/pose_file.h) instead of the log's own, before the first
  // Next(). Sources whose frame times are not known in advance (videos, cameras) refuse it.
  virtual Status UsePoseFile(const std::string& path);

  // Takes the camera's calibration from a file (io/camera_file.h) instead of the log's own, before the first Next():
  // image folders and patterns have none. Fails naming the file when it cannot be read or its resolution is not the
  // images'; sources that are not lists of image files (videos, bags, cameras) refuse it.
  virtual Status UseCameraFile(const std::string& path);

  const std::vector<SkippedFrame>& skipped() const { return skipped_; }

  // Whether the next decoded frame should also keep its colour image (Frame::colour). Image folders, EuRoC
  // logs and videos do; ROS bags and grey images leave it empty.
  void KeepColour(bool keep) { keep_colour_ = keep; }

 protected:
  void RecordSkipped(std::int64_t index, std::string reason);
  bool keep_colour() const { return keep_colour_; }

 private:
  std::vector<SkippedFrame> skipped_;
  bool keep_colour_ = false;
};

}  // namespace patrolmap::io
