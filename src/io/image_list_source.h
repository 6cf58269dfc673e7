// Internal: a FrameSource over a list of timestamped image files, shared by
// the image-folder, printf-pattern and EuRoC readers.
#pragma once

#include <string>
#include <vector>

#include "gps_poses.h"
#include "patrolmap/io/frame_source.h"
#include "patrolmap/io/patrol_sensors.h"

namespace patrolmap::io {

struct ImageEntry {
  TimestampNs timestamp_ns = 0;
  std::string path;
};

struct SpeedSample {
  TimestampNs timestamp_ns = 0;
  double speed_mps = 0.0;
};

class ImageListSource : public FrameSource {
 public:
  // `imu` and `speeds` must be sorted by time (the EuRoC reader checks this).
  ImageListSource(LogInfo info, std::vector<ImageEntry> entries, std::vector<ImuSample> imu = {},
                  std::vector<SpeedSample> speeds = {}, std::vector<GpsSample> gps = {}, PatrolSensors sensors = {});

  Status Next(bool decode_image, Frame* frame) override;
  const LogInfo& info() const override { return info_; }
  void SetFlightId(std::string id) override { info_.flight_id = std::move(id); }
  Status UsePoseFile(const std::string& path) override;
  Status UseCameraFile(const std::string& path) override;
  // Refuses a calibration from `path` whose resolution is not the first readable image's.
  Status CheckResolution(const CameraIntrinsics& camera, const std::string& path) const;

 private:
  void AppendImuUpTo(TimestampNs timestamp_ns, std::vector<ImuSample>* samples);
  // Poses and depth images up to `timestamp_ns` into `frame`, and the detections at exactly that time.
  void AttachSensors(TimestampNs timestamp_ns, Frame* frame);
  // Appends the entries up to `timestamp_ns` from *next on, with the pose at their time.
  void AttachDepth(const std::vector<DepthEntry>& entries, TimestampNs timestamp_ns, std::size_t* next,
                   Frame* frame) const;
  std::optional<double> SpeedAt(TimestampNs timestamp_ns) const;
  std::optional<Eigen::Vector3d> GpsAt(TimestampNs timestamp_ns) const;
  bool Decode(std::int64_t index, const std::string& path, cv::Mat* image, cv::Mat* colour);

  LogInfo info_;
  std::vector<ImageEntry> entries_;
  std::vector<ImuSample> imu_;
  std::vector<SpeedSample> speeds_;
  std::vector<GpsSample> gps_;
  PatrolSensors sensors_;
  std::size_t next_pose_ = 0, next_detection_ = 0, next_depth_ = 0, next_stereo_ = 0;
  std::size_t next_entry_ = 0;
  std::size_t next_imu_ = 0;
  cv::Size first_size_;
  std::vector<unsigned char> header_;  // the head of the frame being decoded (DeclaredSize), kept between frames
};

}  // namespace patrolmap::io
