#include "image_list_source.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <limits>
#include <vector>

#include <spdlog/spdlog.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/core/image_header.h"
#include "patrolmap/io/camera_file.h"
#include "patrolmap/io/pose_file.h"

namespace patrolmap::io {
namespace {

// The most pixels a frame may have (a 9000x7000 photograph): a crafted header that declares more would take
// seconds and gigabytes to decode.
constexpr std::int64_t kMaxFramePixels = 64 << 20;

// The size a PNG or JPEG file's header declares (DeclaredImageSize of its first 64 kB, read into `head`, which a
// caller reading frame after frame keeps).
bool DeclaredSize(const std::string& path, std::vector<unsigned char>* head, std::int64_t* width,
                  std::int64_t* height) {
  std::ifstream stream(path, std::ios::binary);
  head->resize(64 * 1024);
  stream.read(reinterpret_cast<char*>(head->data()), static_cast<std::streamsize>(head->size()));
  return DeclaredImageSize(head->data(), static_cast<std::size_t>(stream.gcount()), width, height);
}

}  // namespace

ImageListSource::ImageListSource(LogInfo info, std::vector<ImageEntry> entries, std::vector<ImuSample> imu,
                                 std::vector<SpeedSample> speeds, std::vector<GpsSample> gps, PatrolSensors sensors)
    : info_(std::move(info)),
      entries_(std::move(entries)),
      imu_(std::move(imu)),
      speeds_(std::move(speeds)),
      gps_(std::move(gps)),
      sensors_(std::move(sensors)) {
  info_.frame_count = static_cast<std::int64_t>(entries_.size());
  info_.has_imu = !imu_.empty();
  info_.has_poses = !sensors_.poses.empty();
  if (info_.has_poses) info_.pose_source = sensors_.pose_source;
  info_.has_detections = !sensors_.detections.empty();
  info_.has_depth = !sensors_.depth.empty();
  info_.has_stereo = info_.stereo.has_value() && !sensors_.stereo.empty();
  info_.has_speed = !speeds_.empty();
}

Status ImageListSource::UsePoseFile(const std::string& path) {
  std::vector<TimestampNs> times(entries_.size());
  std::transform(entries_.begin(), entries_.end(), times.begin(), [](const ImageEntry& e) { return e.timestamp_ns; });
  std::vector<CameraPoseSample> poses;
  PATROLMAP_RETURN_IF_ERROR(ReadPoseFile(path, times, &poses));
  if (info_.has_poses) spdlog::info("{}: camera poses from {}, not the log's state estimate", info_.path, path);
  sensors_.poses = std::move(poses);
  info_.has_poses = true;
  info_.pose_source = kPosesFromFile;
  return Status::Ok();
}

Status ImageListSource::CheckResolution(const CameraIntrinsics& camera, const std::string& path) const {
  // The first image whose header declares its size, or else the first that decodes.
  std::vector<unsigned char> head;
  for (const ImageEntry& entry : entries_) {
    std::int64_t width = 0, height = 0;
    if (!DeclaredSize(entry.path, &head, &width, &height)) {
      const cv::Mat image = cv::imread(entry.path, cv::IMREAD_UNCHANGED);
      if (image.empty()) continue;
      width = image.cols, height = image.rows;
    }
    if (width == camera.width && height == camera.height) return Status::Ok();
    return Status::InvalidArgument(path + ": resolution " + std::to_string(camera.width) + "x" +
                                   std::to_string(camera.height) + ", but " + entry.path + " is " +
                                   std::to_string(width) + "x" + std::to_string(height));
  }
  return Status::Ok();
}

Status ImageListSource::UseCameraFile(const std::string& path) {
  CameraIntrinsics camera;
  Distortion distortion;
  PATROLMAP_RETURN_IF_ERROR(ReadCameraFile(path, &camera, &distortion));
  PATROLMAP_RETURN_IF_ERROR(CheckResolution(camera, path));
  if (info_.camera) spdlog::info("{}: camera calibration from {}, not the log's own", info_.path, path);
  info_.camera = camera;
  info_.camera_distortion = distortion;
  return Status::Ok();
}

Status ImageListSource::Next(bool decode_image, Frame* frame) {
  frame->imu.clear();
  frame->poses.clear();
  frame->depth.clear();
  while (next_entry_ < entries_.size()) {
    const std::int64_t index = static_cast<std::int64_t>(next_entry_);
    const ImageEntry& entry = entries_[next_entry_++];
    AppendImuUpTo(entry.timestamp_ns, &frame->imu);
    // After the last frame nothing else comes: the samples left come with it.
    AttachSensors(next_entry_ == entries_.size() ? std::numeric_limits<TimestampNs>::max() : entry.timestamp_ns, frame);
    frame->pose = PoseAt(sensors_.poses, entry.timestamp_ns);
    frame->image.release();
    frame->colour.release();
    if ((decode_image || !frame->detections.empty()) && !Decode(index, entry.path, &frame->image, &frame->colour)) {
      continue;
    }
    frame->timestamp_ns = entry.timestamp_ns;
    frame->index = index;
    frame->speed_mps = SpeedAt(entry.timestamp_ns);
    frame->gps = GpsAt(entry.timestamp_ns);
    return Status::Ok();
  }
  return Status::EndOfStream();
}

bool ImageListSource::Decode(std::int64_t index, const std::string& path, cv::Mat* image, cv::Mat* colour) {
  std::int64_t width = 0, height = 0;
  if (DeclaredSize(path, &header_, &width, &height) && width * height > kMaxFramePixels) {
    RecordSkipped(index, path + ": declares " + std::to_string(width) + "x" + std::to_string(height) +
                             " pixels, more than a camera frame has (" + std::to_string(kMaxFramePixels) + ")");
    return false;
  }
  if (keep_colour()) {
    const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (raw.type() == CV_8UC3) *colour = raw;
    if (raw.type() == CV_8UC4) cv::cvtColor(raw, *colour, cv::COLOR_BGRA2BGR);
  }
  if (!colour->empty()) {
    cv::cvtColor(*colour, *image, cv::COLOR_BGR2GRAY);
  } else {
    *image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  }
  if (image->empty()) {
    RecordSkipped(index, path + ": missing or unreadable image");
    return false;
  }
  if (first_size_.empty()) first_size_ = image->size();
  if (image->size() != first_size_) {
    RecordSkipped(index, path + ": image is " + std::to_string(image->cols) + "x" + std::to_string(image->rows) +
                             ", the log's first image is " + std::to_string(first_size_.width) + "x" +
                             std::to_string(first_size_.height));
    return false;
  }
  return true;
}

void ImageListSource::AttachDepth(const std::vector<DepthEntry>& entries, TimestampNs timestamp_ns, std::size_t* next,
                                  Frame* frame) const {
  for (; *next < entries.size() && entries[*next].timestamp_ns <= timestamp_ns; ++*next) {
    const DepthEntry& entry = entries[*next];
    DepthSample sample;
    sample.timestamp_ns = entry.timestamp_ns;
    sample.path = entry.path;
    sample.right_path = entry.right_path;
    sample.pose = PoseAt(sensors_.poses, entry.timestamp_ns);
    frame->depth.push_back(std::move(sample));
  }
}

void ImageListSource::AttachSensors(TimestampNs timestamp_ns, Frame* frame) {
  const std::vector<CameraPoseSample>& poses = sensors_.poses;
  for (; next_pose_ < poses.size() && poses[next_pose_].timestamp_ns <= timestamp_ns; ++next_pose_) {
    frame->poses.push_back(poses[next_pose_]);
  }
  AttachDepth(sensors_.depth, timestamp_ns, &next_depth_, frame);
  AttachDepth(sensors_.stereo, timestamp_ns, &next_stereo_, frame);
  // Detections between frames belong to none and are dropped; those of a skipped frame go with it.
  const std::vector<ObjectObservation>& detections = sensors_.detections;
  frame->detections.clear();
  const TimestampNs frame_ns = std::min(timestamp_ns, entries_[next_entry_ - 1].timestamp_ns);
  while (next_detection_ < detections.size() && detections[next_detection_].timestamp_ns < frame_ns) ++next_detection_;
  while (next_detection_ < detections.size() && detections[next_detection_].timestamp_ns == frame_ns) {
    frame->detections.push_back(detections[next_detection_++]);
  }
}

void ImageListSource::AppendImuUpTo(TimestampNs timestamp_ns, std::vector<ImuSample>* samples) {
  while (next_imu_ < imu_.size() && imu_[next_imu_].timestamp_ns <= timestamp_ns) {
    samples->push_back(imu_[next_imu_++]);
  }
}

std::optional<double> ImageListSource::SpeedAt(TimestampNs timestamp_ns) const {
  if (speeds_.empty()) return std::nullopt;
  const auto after = std::lower_bound(speeds_.begin(), speeds_.end(), timestamp_ns,
                                      [](const SpeedSample& sample, TimestampNs t) { return sample.timestamp_ns < t; });
  if (after == speeds_.begin()) return after->speed_mps;
  if (after == speeds_.end()) return speeds_.back().speed_mps;
  const SpeedSample& before = *(after - 1);
  const double span = static_cast<double>(after->timestamp_ns - before.timestamp_ns);
  const double weight = static_cast<double>(timestamp_ns - before.timestamp_ns) / span;
  return before.speed_mps + weight * (after->speed_mps - before.speed_mps);
}

std::optional<Eigen::Vector3d> ImageListSource::GpsAt(TimestampNs timestamp_ns) const {
  if (gps_.empty()) return std::nullopt;
  const auto after = std::lower_bound(gps_.begin(), gps_.end(), timestamp_ns,
                                      [](const GpsSample& sample, TimestampNs t) { return sample.timestamp_ns < t; });
  if (after == gps_.begin()) return after->position;
  if (after == gps_.end()) return gps_.back().position;
  const GpsSample& before = *(after - 1);
  const double weight = static_cast<double>(timestamp_ns - before.timestamp_ns) /
                        static_cast<double>(after->timestamp_ns - before.timestamp_ns);
  return Eigen::Vector3d(before.position + weight * (after->position - before.position));
}

}  // namespace patrolmap::io
