// A FrameSource over a ROS bag (bag.h): the chosen topics streamed in record-time order, camera messages
// held in a short queue until the samples that belong to them have been read (the IMU up to the next
// frame, a pose after the frame's time), then decoded one at a time.
#include <algorithm>
#include <deque>
#include <filesystem>
#include <map>
#include <set>

#include <spdlog/spdlog.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bag_file.h"
#include "gps_poses.h"
#include "image_times.h"
#include "patrolmap/core/files.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/pose_file.h"
#include "patrolmap/io/readers.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

using rosmsg::MessageKind;

// Camera messages held while waiting for a pose after their time; beyond, a frame goes without one.
constexpr std::size_t kMaxPendingFrames = 64;

bool IsImageKind(MessageKind kind) { return kind == MessageKind::kImage || kind == MessageKind::kCompressedImage; }
bool IsPoseKind(MessageKind kind) {
  return kind == MessageKind::kPoseStamped || kind == MessageKind::kPoseWithCovarianceStamped ||
         kind == MessageKind::kOdometry;
}

bool IsDepthName(const std::string& name) { return name.find("depth") != std::string::npos; }

// The topic chosen for one role: the named one (which must exist and have a fitting type) or, when
// `by_default`, the first of a fitting type that `default_name` accepts. -1 when there is none.
Status ChooseTopic(const std::string& path, const std::vector<BagTopic>& topics, const char* role,
                   const std::string& wanted, bool (*fits)(MessageKind), int* chosen,
                   bool (*default_name)(const std::string&) = nullptr) {
  *chosen = -1;
  for (std::size_t i = 0; i < topics.size(); ++i) {
    if (!wanted.empty() && topics[i].name != wanted) continue;
    const bool fitting = fits(rosmsg::KindOfType(topics[i].type));
    if (wanted.empty() && (!fitting || (default_name != nullptr && !default_name(topics[i].name)))) continue;
    if (!fitting) {
      return Status::InvalidArgument(path + ", topic " + topics[i].name + ": type " + topics[i].type +
                                     " cannot be the " + role + " topic");
    }
    *chosen = static_cast<int>(i);
    return Status::Ok();
  }
  if (!wanted.empty()) {
    std::string names;
    for (const BagTopic& topic : topics) names += (names.empty() ? "" : ", ") + topic.name;
    return Status::NotFound(path + ": no topic " + wanted + " (--topic " + role + "=); the bag has " +
                            (names.empty() ? "no topics" : names));
  }
  return Status::Ok();
}

// The topics a flight is read from.
struct BagRoles {
  int camera = -1, camera_info = -1, imu = -1, gps = -1, pose = -1, transforms = -1;
  int depth = -1, right = -1, right_info = -1;
};

Status ChooseRoles(const std::string& path, const std::vector<BagTopic>& topics, const TopicChoice& choice,
                   BagRoles* roles) {
  // By default the camera is the first image topic not named for depth, the depth the first named for it.
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(path, topics, "camera", choice.camera, IsImageKind, &roles->camera,
                                        [](const std::string& name) { return !IsDepthName(name); }));
  if (roles->camera < 0) {
    return Status::DataLoss(path + ": no sensor_msgs/Image or CompressedImage topic (patrolmap info " + path +
                            " lists its topics)");
  }
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(
      path, topics, "camera_info", choice.camera_info, [](MessageKind k) { return k == MessageKind::kCameraInfo; },
      &roles->camera_info));
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(
      path, topics, "imu", choice.imu, [](MessageKind k) { return k == MessageKind::kImu; }, &roles->imu));
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(
      path, topics, "gps", choice.gps, [](MessageKind k) { return k == MessageKind::kNavSatFix; }, &roles->gps));
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(path, topics, "pose", choice.pose, IsPoseKind, &roles->pose));
  PATROLMAP_RETURN_IF_ERROR(ChooseTopic(
      path, topics, "depth", choice.depth, [](MessageKind k) { return k == MessageKind::kImage; }, &roles->depth,
      IsDepthName));
  if (!choice.right.empty()) {
    PATROLMAP_RETURN_IF_ERROR(ChooseTopic(path, topics, "right", choice.right, IsImageKind, &roles->right));
    // ROS names a camera's calibration beside its images: /cam1/image_raw -> /cam1/camera_info.
    const std::string info = choice.right.substr(0, choice.right.rfind('/') + 1) + "camera_info";
    for (std::size_t i = 0; i < topics.size(); ++i) {
      if (topics[i].name == info && rosmsg::KindOfType(topics[i].type) == MessageKind::kCameraInfo) {
        roles->right_info = static_cast<int>(i);
      }
    }
  }
  for (std::size_t i = 0; i < topics.size(); ++i) {
    if (topics[i].name == "/tf_static" && rosmsg::KindOfType(topics[i].type) == MessageKind::kTransforms) {
      roles->transforms = static_cast<int>(i);
    }
  }
  return Status::Ok();
}

// The static transforms of a bag as a forest of frames: each frame's rotation in its tree's root.
class FrameTree {
 public:
  void Add(const rosmsg::TransformMessage& transform) {
    parent_[transform.child_frame] = {transform.header.frame_id, transform.rotation};
  }

  // The rotation taking vectors of `source` into `target`, when both frames are known and linked.
  std::optional<Eigen::Quaterniond> Rotation(const std::string& target, const std::string& source) const {
    if (target == source) return Eigen::Quaterniond::Identity();
    std::string target_root, source_root;
    const Eigen::Quaterniond root_from_target = FromRoot(target, &target_root);
    const Eigen::Quaterniond root_from_source = FromRoot(source, &source_root);
    if (target_root != source_root || (target_root == target && source_root == source)) return std::nullopt;
    return root_from_target.conjugate() * root_from_source;
  }

 private:
  Eigen::Quaterniond FromRoot(const std::string& frame, std::string* root) const {
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    std::string at = frame;
    for (std::size_t depth = 0; depth < parent_.size(); ++depth) {  // a cycle ends here
      const auto parent = parent_.find(at);
      if (parent == parent_.end()) break;
      rotation = parent->second.second * rotation;
      at = parent->second.first;
    }
    *root = at;
    return rotation;
  }

  std::map<std::string, std::pair<std::string, Eigen::Quaterniond>> parent_;
};

// Reads at most `limit` messages of one topic (0: all), each handed to `use`.
template <typename Use>
Status ForEachMessage(BagFile* bag, int topic, std::size_t limit, Use use) {
  std::unique_ptr<BagStream> stream;
  PATROLMAP_RETURN_IF_ERROR(bag->Stream({topic}, limit, &stream));
  BagMessage message;
  while (true) {
    const Status status = stream->Next(&message);
    if (status.code() == StatusCode::kEndOfStream) return Status::Ok();
    PATROLMAP_RETURN_IF_ERROR(status);
    PATROLMAP_RETURN_IF_ERROR(use(message));
  }
}

Status TopicError(const std::string& path, const BagTopic& topic, const Status& status) {
  return Status::DataLoss(path + ", topic " + topic.name + " (" + topic.type + "): " + status.message());
}

// A sample of a slowly varying quantity (GPS position, speed) interpolated at frame times.
template <typename Value>
struct TimedValue {
  TimestampNs timestamp_ns = 0;
  Value value{};
};

// The value at `t` from `samples` (ascending): interpolated between the two around it, the first before
// them and the last after them; samples before the one at or before `t` are dropped.
template <typename Value>
std::optional<Value> ValueAt(std::deque<TimedValue<Value>>* samples, TimestampNs t) {
  while (samples->size() >= 2 && (*samples)[1].timestamp_ns <= t) samples->pop_front();
  if (samples->empty()) return std::nullopt;
  const TimedValue<Value>& before = samples->front();
  if (samples->size() == 1 || before.timestamp_ns >= t) return before.value;
  const TimedValue<Value>& after = (*samples)[1];
  const double weight =
      static_cast<double>(t - before.timestamp_ns) / static_cast<double>(after.timestamp_ns - before.timestamp_ns);
  return Value(before.value + weight * (after.value - before.value));
}

// Converts a decoded image message to the frame's 8-bit grey image; fails naming the problem.
Status ToGrey(const rosmsg::ImageMessage& image, cv::Mat* grey) {
  if (image.compressed) {
    if (image.size == 0 || image.data == nullptr) return Status::DataLoss("compressed image of 0 bytes");
    const cv::Mat bytes(1, static_cast<int>(image.size), CV_8UC1, const_cast<std::uint8_t*>(image.data));
    try {
      *grey = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception&) {
      grey->release();
    }
    if (grey->empty()) return Status::DataLoss("compressed image (" + image.encoding + ") does not decode");
    return Status::Ok();
  }
  static const std::map<std::string, std::pair<int, int>> kEncodings = {
      // encoding -> (OpenCV type, conversion to grey; -1: none)
      {"mono8", {CV_8UC1, -1}},
      {"8UC1", {CV_8UC1, -1}},
      {"mono16", {CV_16UC1, -1}},
      {"16UC1", {CV_16UC1, -1}},
      {"bgr8", {CV_8UC3, cv::COLOR_BGR2GRAY}},
      {"rgb8", {CV_8UC3, cv::COLOR_RGB2GRAY}},
      {"bgra8", {CV_8UC4, cv::COLOR_BGRA2GRAY}},
      {"rgba8", {CV_8UC4, cv::COLOR_RGBA2GRAY}},
  };
  const auto encoding = kEncodings.find(image.encoding);
  if (encoding == kEncodings.end()) {
    return Status::DataLoss("encoding '" + image.encoding + "' is not one of mono8, mono16, bgr8, rgb8, bgra8, rgba8");
  }
  const int type = encoding->second.first;
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * CV_ELEM_SIZE(type);
  if (image.width == 0 || image.height == 0 || image.width > 1 << 15 || image.height > 1 << 15 ||
      image.step < row_bytes || static_cast<std::size_t>(image.step) * image.height > image.size) {
    return Status::DataLoss("image of " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", step " +
                            std::to_string(image.step) + " does not fit its " + std::to_string(image.size) + " bytes");
  }
  const cv::Mat view(static_cast<int>(image.height), static_cast<int>(image.width), type,
                     const_cast<std::uint8_t*>(image.data), image.step);
  if (type == CV_16UC1) {
    cv::Mat wide = view;
    if (image.big_endian) {
      wide = view.clone();
      wide.forEach<std::uint16_t>(
          [](std::uint16_t& v, const int*) { v = static_cast<std::uint16_t>(v << 8 | v >> 8); });
    }
    wide.convertTo(*grey, CV_8UC1, 1.0 / 256.0);
  } else if (encoding->second.second < 0) {
    view.copyTo(*grey);
  } else {
    cv::cvtColor(view, *grey, encoding->second.second);
  }
  return Status::Ok();
}

// Converts a depth image message (16UC1 or mono16 in millimetres, 32FC1 in metres) to metres, 0 where
// there is no return.
Status ToMetres(const rosmsg::ImageMessage& image, cv::Mat* metres) {
  const bool millimetres = image.encoding == "16UC1" || image.encoding == "mono16";
  if (!millimetres && image.encoding != "32FC1") {
    return Status::DataLoss("depth encoding '" + image.encoding + "' is not 16UC1 [mm] or 32FC1 [m]");
  }
  const int type = millimetres ? CV_16UC1 : CV_32FC1;
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * CV_ELEM_SIZE(type);
  if (image.width == 0 || image.height == 0 || image.width > 1 << 15 || image.height > 1 << 15 ||
      image.step < row_bytes || static_cast<std::size_t>(image.step) * image.height > image.size || image.big_endian) {
    return Status::DataLoss("depth image of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                            " does not fit its bytes (or is big-endian)");
  }
  const cv::Mat view(static_cast<int>(image.height), static_cast<int>(image.width), type,
                     const_cast<std::uint8_t*>(image.data), image.step);
  view.convertTo(*metres, CV_32FC1, millimetres ? 0.001 : 1.0);
  metres->forEach<float>([](float& v, const int*) {
    if (!std::isfinite(v) || v < 0.0f) v = 0.0f;
  });
  return Status::Ok();
}

// A camera message waiting for its samples: its bytes and its time.
struct PendingFrame {
  BagMessage message;
  rosmsg::ImageMessage image;  // decoded once; its data points into message.bytes (a move keeps the buffer)
  TimestampNs timestamp_ns = 0;
  std::int64_t index = 0;
};

class BagSource : public FrameSource {
 public:
  // With `poses_from_gps` the camera poses come from the GPS fixes and the IMU's attitude (no pose topic).
  BagSource(LogInfo info, std::unique_ptr<BagFile> bag, BagRoles roles, std::unique_ptr<BagStream> stream,
            std::optional<Eigen::Quaterniond> body_from_camera, bool poses_from_gps)
      : poses_from_gps_(poses_from_gps),
        info_(std::move(info)),
        bag_(std::move(bag)),
        roles_(roles),
        stream_(std::move(stream)),
        body_from_camera_(body_from_camera.value_or(Eigen::Quaterniond::Identity())) {}

  const LogInfo& info() const override { return info_; }
  void SetFlightId(std::string id) override { info_.flight_id = std::move(id); }

  Status UsePoseFile(const std::string& path) override {
    std::vector<TimestampNs> times;
    PATROLMAP_RETURN_IF_ERROR(bag_->Times(roles_.camera, &times));
    std::vector<CameraPoseSample> poses;
    PATROLMAP_RETURN_IF_ERROR(ReadPoseFile(path, times, &poses));
    if (info_.has_poses) spdlog::info("{}: camera poses from {}, not the bag's pose topic", info_.path, path);
    file_poses_ = std::move(poses);
    roles_.pose = -1;
    poses_from_gps_ = false;
    info_.has_poses = true;
    info_.pose_source = kPosesFromFile;
    return Status::Ok();
  }

  Status Next(bool decode_image, Frame* frame) override {
    frame->imu.clear();
    frame->poses.clear();
    frame->depth.clear();
    frame->detections.clear();
    while (true) {
      PATROLMAP_RETURN_IF_ERROR(Fill());
      if (pending_.empty()) return Status::EndOfStream();
      PendingFrame& next = pending_.front();
      const bool ok = Emit(decode_image, next, frame);
      spare_.push_back(std::move(next.message));
      pending_.pop_front();
      if (ok) return Status::Ok();
    }
  }

 private:
  // Reads until two frames wait (so the first has the IMU up to the second) and the first has a pose after
  // its time, or the bag ends.
  Status Fill() {
    while (!ended_ && pending_.size() < kMaxPendingFrames && (pending_.size() < 2 || WantsPose())) {
      BagMessage message;
      if (!spare_.empty()) {
        message = std::move(spare_.back());
        spare_.pop_back();
      }
      const Status status = stream_->Next(&message);
      if (status.code() == StatusCode::kEndOfStream) {
        ended_ = true;
        break;
      }
      PATROLMAP_RETURN_IF_ERROR(status);
      if (message.topic == roles_.camera) {
        PATROLMAP_RETURN_IF_ERROR(Enqueue(std::move(message)));
      } else {
        PATROLMAP_RETURN_IF_ERROR(Consume(message));
        spare_.push_back(std::move(message));
      }
    }
    return Status::Ok();
  }

  bool WantsPose() const {
    return (roles_.pose >= 0 || poses_from_gps_) &&
           (poses_.empty() || poses_.back().timestamp_ns < pending_.front().timestamp_ns);
  }

  Status Enqueue(BagMessage message) {
    rosmsg::ImageMessage image;
    const bool compressed = rosmsg::KindOfType(Topic(roles_.camera).type) == MessageKind::kCompressedImage;
    const Status status = rosmsg::DecodeImage(message.bytes, bag_->wire(), compressed, &image);
    if (!status.ok()) {
      // A damaged frame is skipped like an unreadable image file; a topic whose very first message does not
      // decode was refused when the bag was opened (its type does not match).
      RecordSkipped(next_index_, TopicError(info_.path, Topic(roles_.camera), status).message() + " (message " +
                                     std::to_string(next_index_) + ")");
      ++next_index_;
      spare_.push_back(std::move(message));
      return Status::Ok();
    }
    const TimestampNs t = StampOrRecord(image.header, message.record_ns);
    pending_.push_back({std::move(message), std::move(image), t, next_index_++});
    return Status::Ok();
  }

  static TimestampNs StampOrRecord(const rosmsg::Header& header, TimestampNs record_ns) {
    return header.stamp_ns > 0 ? header.stamp_ns : record_ns;
  }

  const BagTopic& Topic(int index) const { return bag_->topics()[index]; }

  // A sensor message: into the samples waiting for frames.
  Status Consume(const BagMessage& message) {
    const BagTopic& topic = Topic(message.topic);
    Status status;
    if (message.topic == roles_.imu) {
      rosmsg::ImuMessage imu;
      status = rosmsg::DecodeImu(message.bytes, bag_->wire(), &imu);
      const TimestampNs t = StampOrRecord(imu.header, message.record_ns);
      if (status.ok() && (imu_.empty() || t > imu_.back().timestamp_ns) && t > last_imu_ns_) {
        imu_.push_back({t, imu.gyro, imu.accel});
      }
      if (status.ok() && imu.orientation) attitude_ = *imu.orientation;
    } else if (message.topic == roles_.gps) {
      rosmsg::NavSatFixMessage fix;
      status = rosmsg::DecodeNavSatFix(message.bytes, bag_->wire(), &fix);
      if (status.ok() && fix.status >= 0) {
        const TimestampNs t = StampOrRecord(fix.header, message.record_ns);
        AppendTimed(&gps_, t, fix.position);
        if (poses_from_gps_ && attitude_) AddPose(PoseFromFix(fix.position), t);
      }
    } else if (message.topic == roles_.depth) {
      status = ConsumeDepth(message);
    } else if (message.topic == roles_.right) {
      status = ConsumeRight(message);
    } else if (message.topic == roles_.pose) {
      rosmsg::PoseMessage pose;
      status = rosmsg::DecodePose(message.bytes, bag_->wire(), rosmsg::KindOfType(topic.type), &pose);
      if (status.ok()) AddPose(pose, StampOrRecord(pose.header, message.record_ns));
    }
    if (!status.ok()) return SkipSample(message.topic, status);  // damaged: the first message decoded at opening
    return Status::Ok();
  }

  Status ConsumeDepth(const BagMessage& message) {
    rosmsg::ImageMessage image;
    PATROLMAP_RETURN_IF_ERROR(rosmsg::DecodeImage(message.bytes, bag_->wire(), false, &image));  // skipped above
    DepthSample sample;
    sample.timestamp_ns = StampOrRecord(image.header, message.record_ns);
    const Status status = ToMetres(image, &sample.image);
    if (!status.ok()) return SkipSample(message.topic, status);
    if (depth_.empty() || sample.timestamp_ns > depth_.back().timestamp_ns) depth_.push_back(std::move(sample));
    return Status::Ok();
  }

  Status ConsumeRight(const BagMessage& message) {
    rosmsg::ImageMessage image;
    const bool compressed = rosmsg::KindOfType(Topic(message.topic).type) == MessageKind::kCompressedImage;
    PATROLMAP_RETURN_IF_ERROR(rosmsg::DecodeImage(message.bytes, bag_->wire(), compressed, &image));
    TimedValue<cv::Mat> right{StampOrRecord(image.header, message.record_ns), cv::Mat()};
    const Status status = ToGrey(image, &right.value);
    if (!status.ok()) return SkipSample(message.topic, status);
    if (right_.empty() || right.timestamp_ns > right_.back().timestamp_ns) right_.push_back(std::move(right));
    while (right_.size() > kMaxPendingFrames) right_.pop_front();
    return Status::Ok();
  }

  // A sample that is damaged or cannot be used: skipped, with a warning the first time for its topic.
  Status SkipSample(int topic, const Status& why) {
    if (warned_topics_.insert(topic).second) {
      spdlog::warn("{}, topic {}: {}; such messages are skipped", info_.path, Topic(topic).name, why.message());
    }
    return Status::Ok();
  }

  template <typename Value>
  static void AppendTimed(std::deque<TimedValue<Value>>* samples, TimestampNs t, const Value& value) {
    if (samples->empty() || t > samples->back().timestamp_ns) samples->push_back({t, value});
  }

  // A fix and the latest attitude as a pose: east, north, up [m] about the grid point nearest the first fix
  // (gps_poses.h: every flight over a site shares the frame), turned by the IMU's attitude.
  rosmsg::PoseMessage PoseFromFix(const Eigen::Vector3d& fix) {
    if (!gps_origin_) gps_origin_ = GpsFrameOrigin(fix);
    rosmsg::PoseMessage pose;
    pose.position = EastNorthUp(fix, *gps_origin_);
    pose.rotation = *attitude_;
    return pose;
  }

  void AddPose(const rosmsg::PoseMessage& pose, TimestampNs t) {
    if (!poses_.empty() && t <= poses_.back().timestamp_ns) return;
    CameraPoseSample sample;
    sample.timestamp_ns = t;
    sample.position = pose.position;
    sample.rotation = (pose.rotation * body_from_camera_).normalized();
    poses_.push_back(sample);
    if (pose.has_velocity) AppendTimed(&speeds_, t, pose.velocity.norm());
  }

  // Hands `pending` out as `frame` with its samples; false when its image is skipped.
  bool Emit(bool decode_image, const PendingFrame& pending, Frame* frame) {
    const TimestampNs t = pending.timestamp_ns;
    if (t <= last_frame_ns_) {
      RecordSkipped(pending.index, info_.path + ", topic " + Topic(roles_.camera).name + ": frame at " +
                                       std::to_string(t) + " ns is not after the previous one");
      return false;
    }
    while (!imu_.empty() && imu_.front().timestamp_ns <= t) {
      frame->imu.push_back(imu_.front());
      last_imu_ns_ = imu_.front().timestamp_ns;
      imu_.pop_front();
    }
    AttachDepth(t, frame);
    AttachPoses(t, frame);
    frame->image.release();
    while (!right_.empty() && right_.front().timestamp_ns < t) right_.pop_front();
    const bool paired = !right_.empty() && right_.front().timestamp_ns == t && info_.has_stereo;
    if (decode_image || paired) {
      Status status = ToGrey(pending.image, &frame->image);
      if (status.ok() && first_size_.empty()) first_size_ = frame->image.size();
      if (status.ok() && frame->image.size() != first_size_) {
        status = Status::DataLoss("image is " + std::to_string(frame->image.cols) + "x" +
                                  std::to_string(frame->image.rows) + ", the bag's first is " +
                                  std::to_string(first_size_.width) + "x" + std::to_string(first_size_.height));
      }
      if (!status.ok()) {
        RecordSkipped(pending.index, info_.path + ", topic " + Topic(roles_.camera).name + ", message " +
                                         std::to_string(pending.index) + ": " + status.message());
        return false;
      }
    }
    if (paired) {
      DepthSample pair;
      pair.timestamp_ns = t;
      pair.image = frame->image;  // a new buffer every frame (released above)
      pair.right_image = std::move(right_.front().value);
      pair.pose = PoseNear(t);
      right_.pop_front();
      frame->depth.push_back(std::move(pair));
    }
    last_frame_ns_ = t;
    frame->timestamp_ns = t;
    frame->index = pending.index;
    frame->speed_mps = ValueAt(&speeds_, t);
    frame->gps = ValueAt(&gps_, t);
    return true;
  }

  std::optional<CameraPoseSample> PoseNear(TimestampNs t) const {
    return file_poses_.empty() ? PoseAt(poses_, t) : PoseAt(file_poses_, t);
  }

  // Depth images up to the frame's time, each with the pose at its own time (before AttachPoses drops the
  // poses before the frame).
  void AttachDepth(TimestampNs t, Frame* frame) {
    while (!depth_.empty() && depth_.front().timestamp_ns <= t) {
      frame->depth.push_back(std::move(depth_.front()));
      frame->depth.back().pose = PoseNear(frame->depth.back().timestamp_ns);
      depth_.pop_front();
    }
  }

  void AttachPoses(TimestampNs t, Frame* frame) {
    if (!file_poses_.empty()) {
      for (; next_file_pose_ < file_poses_.size() && file_poses_[next_file_pose_].timestamp_ns <= t;
           ++next_file_pose_) {
        frame->poses.push_back(file_poses_[next_file_pose_]);
      }
      frame->pose = PoseAt(file_poses_, t);
      return;
    }
    // Keeps the last pose at or before the frame for the next frame's interpolation.
    for (const CameraPoseSample& pose : poses_) {
      if (pose.timestamp_ns > t) break;
      if (pose.timestamp_ns > last_pose_handed_ns_) frame->poses.push_back(pose);
    }
    if (!frame->poses.empty()) last_pose_handed_ns_ = frame->poses.back().timestamp_ns;
    frame->pose = PoseAt(poses_, t);
    std::size_t passed = 0;
    while (passed + 1 < poses_.size() && poses_[passed + 1].timestamp_ns <= t) ++passed;
    poses_.erase(poses_.begin(), poses_.begin() + static_cast<std::ptrdiff_t>(passed));
  }

  bool poses_from_gps_;
  std::optional<Eigen::Quaterniond> attitude_;  // the IMU's latest, for poses from GPS
  std::optional<Eigen::Vector3d> gps_origin_;   // of the poses from GPS (GpsFrameOrigin)
  LogInfo info_;
  std::unique_ptr<BagFile> bag_;
  BagRoles roles_;
  std::unique_ptr<BagStream> stream_;
  Eigen::Quaterniond body_from_camera_;  // kept a quaternion: the poses equal the EuRoC reader's to the bit
  std::deque<PendingFrame> pending_;
  std::vector<BagMessage> spare_;  // buffers of read messages, reused
  bool ended_ = false;
  std::int64_t next_index_ = 0;
  TimestampNs last_frame_ns_ = -1, last_imu_ns_ = -1, last_pose_handed_ns_ = -1;
  std::deque<ImuSample> imu_;
  std::vector<CameraPoseSample> poses_;  // from the last one at or before the last frame on
  std::deque<TimedValue<Eigen::Vector3d>> gps_;
  std::deque<TimedValue<double>> speeds_;
  std::deque<DepthSample> depth_;          // depth images waiting for their frame
  std::deque<TimedValue<cv::Mat>> right_;  // right images waiting for the left one of their time
  std::set<int> warned_topics_;
  std::vector<CameraPoseSample> file_poses_;
  std::size_t next_file_pose_ = 0;
  cv::Size first_size_;
};

Status OpenBagFile(const std::string& path, std::unique_ptr<BagFile>* bag) {
  if (!PathExists(path)) return Status::NotFound(path + ": no such file or folder");
  const fs::path location(path);
  if (fs::is_directory(location)) return OpenRos2Bag(path, bag);
  if (location.extension() == ".db3") return OpenRos2Bag(location.parent_path().string(), bag);
  return OpenRos1Bag(path, bag);
}

// The first message of `topic` decoded by `decode`; false when the topic has none.
// Decodes a message of `topic` as `Message`: images compressed or not by the topic's type, poses by its kind.
Status DecodeAs(const BagTopic& topic, rosmsg::Wire wire, const std::vector<std::uint8_t>& bytes,
                rosmsg::ImageMessage* message) {
  return rosmsg::DecodeImage(bytes, wire, rosmsg::KindOfType(topic.type) == MessageKind::kCompressedImage, message);
}
Status DecodeAs(const BagTopic& topic, rosmsg::Wire wire, const std::vector<std::uint8_t>& bytes,
                rosmsg::PoseMessage* message) {
  return rosmsg::DecodePose(bytes, wire, rosmsg::KindOfType(topic.type), message);
}
Status DecodeAs(const BagTopic&, rosmsg::Wire wire, const std::vector<std::uint8_t>& bytes,
                rosmsg::CameraInfoMessage* message) {
  return rosmsg::DecodeCameraInfo(bytes, wire, message);
}
Status DecodeAs(const BagTopic&, rosmsg::Wire wire, const std::vector<std::uint8_t>& bytes,
                rosmsg::ImuMessage* message) {
  return rosmsg::DecodeImu(bytes, wire, message);
}
Status DecodeAs(const BagTopic&, rosmsg::Wire wire, const std::vector<std::uint8_t>& bytes,
                rosmsg::NavSatFixMessage* message) {
  return rosmsg::DecodeNavSatFix(bytes, wire, message);
}

// The first message of `topic` (none: -1) into `message`; `found` false when there is none. A first message
// that does not decode refuses the topic: its type does not match its bytes.
template <typename Message>
Status FirstMessage(BagFile* bag, const std::string& path, int topic, Message* message, bool* found) {
  *found = false;
  if (topic < 0) return Status::Ok();
  const BagTopic& info = bag->topics()[topic];
  return ForEachMessage(bag, topic, 1, [&](const BagMessage& m) {
    const Status status = DecodeAs(info, bag->wire(), m.bytes, message);
    if (!status.ok()) return TopicError(path, info, status);
    *found = true;
    return Status::Ok();
  });
}

CameraIntrinsics IntrinsicsOf(const rosmsg::CameraInfoMessage& info) {
  return {info.k[0], info.k[4], info.k[2], info.k[5], static_cast<int>(info.width), static_cast<int>(info.height)};
}

// A camera info's distortion (plumb_bob: k1, k2, p1, p2); fails naming a model or a term that is not undone.
Status DistortionOf(const rosmsg::CameraInfoMessage& camera, Distortion* distortion) {
  const std::string& model = camera.distortion_model;
  if (!model.empty() && model != "plumb_bob" && model != "radial-tangential") {
    return Status::InvalidArgument("distortion model '" + model + "' is not plumb_bob, the only one undone");
  }
  if (camera.distortion.size() > 4 && std::abs(camera.distortion[4]) > 1e-9) {
    return Status::InvalidArgument("a k3 distortion term, which is not undone");
  }
  Distortion read{};
  for (std::size_t i = 0; i < 4; ++i) read[i] = i < camera.distortion.size() ? camera.distortion[i] : 0.0;
  if (!PlausibleDistortion(read)) {
    return Status::InvalidArgument("distortion coefficients that are not finite or beyond " +
                                   std::to_string(static_cast<int>(kMaxDistortionCoefficient)));
  }
  *distortion = read;
  return Status::Ok();
}

// A stereo pair's calibration from the two cameras' CameraInfo (ROS's stereo convention: R rotates each
// camera into the rectified frame, the right P holds -fx * baseline); fails saying why it cannot be used.
Status StereoFromCameraInfo(const rosmsg::CameraInfoMessage& left, const rosmsg::CameraInfoMessage& right,
                            StereoCalibration* pair) {
  PATROLMAP_RETURN_IF_ERROR(DistortionOf(left, &pair->left_distortion));
  PATROLMAP_RETURN_IF_ERROR(DistortionOf(right, &pair->right_distortion));
  for (const rosmsg::CameraInfoMessage* camera : {&left, &right}) {
    if (!IntrinsicsOf(*camera).valid()) return Status::InvalidArgument("camera info without intrinsics");
  }
  if (!(right.p[0] > 0.0) || !(std::abs(right.p[3]) > 0.0)) {
    return Status::InvalidArgument("the right camera info's P holds no baseline (P[3] = -fx * baseline)");
  }
  pair->left = IntrinsicsOf(left);
  pair->right = IntrinsicsOf(right);
  using RowMajor = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const Eigen::Matrix3d left_rectified = Eigen::Map<const RowMajor>(left.r.data());
  const Eigen::Matrix3d right_rectified = Eigen::Map<const RowMajor>(right.r.data());
  const double baseline = -right.p[3] / right.p[0];
  // x_right = R_r^T (R_l x_left - (baseline, 0, 0))
  pair->right_from_left_rotation = right_rectified.transpose() * left_rectified;
  pair->right_from_left_translation = -right_rectified.transpose() * Eigen::Vector3d(baseline, 0.0, 0.0);
  return Status::Ok();
}

// The first message of each chosen topic: the sensors' frame ids, the cameras' calibration, and a check that
// every topic's type matches its bytes.
struct FirstMessages {
  rosmsg::ImageMessage image;
  rosmsg::CameraInfoMessage camera_info, right_info;
  rosmsg::ImuMessage imu;
  rosmsg::PoseMessage pose;
  bool has_camera_info = false, has_right_info = false;
};

Status ReadFirstMessages(BagFile* bag, const std::string& path, const BagRoles& roles, FirstMessages* first) {
  bool found = false;
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.camera, &first->image, &found));
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.camera_info, &first->camera_info, &first->has_camera_info));
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.right_info, &first->right_info, &first->has_right_info));
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.imu, &first->imu, &found));
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.pose, &first->pose, &found));
  rosmsg::NavSatFixMessage fix;
  PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, roles.gps, &fix, &found));
  for (const int topic : {roles.depth, roles.right}) {
    rosmsg::ImageMessage image;
    PATROLMAP_RETURN_IF_ERROR(FirstMessage(bag, path, topic, &image, &found));
  }
  return Status::Ok();
}

Status ReadFrameTree(BagFile* bag, const std::string& path, int topic, FrameTree* tree) {
  if (topic < 0) return Status::Ok();
  return ForEachMessage(bag, topic, 0, [&](const BagMessage& m) {
    std::vector<rosmsg::TransformMessage> transforms;
    const Status status = rosmsg::DecodeTransforms(m.bytes, bag->wire(), &transforms);
    if (!status.ok()) return TopicError(path, bag->topics()[topic], status);
    for (const rosmsg::TransformMessage& transform : transforms) tree->Add(transform);
    return Status::Ok();
  });
}

// The rotations between the camera, the IMU and the frame the poses move, from /tf_static.
void SetRotations(const BagFile& bag, const std::string& path, const BagRoles& roles, const FirstMessages& first,
                  const FrameTree& tree, LogInfo* info, std::optional<Eigen::Quaterniond>* body_from_camera,
                  bool* poses_from_gps) {
  const std::string& camera = first.image.header.frame_id;
  const std::string& imu = first.imu.header.frame_id;
  if (roles.imu >= 0) {
    const std::optional<Eigen::Quaterniond> camera_from_imu = tree.Rotation(camera, imu);
    if (camera_from_imu) info->camera_from_imu = camera_from_imu->toRotationMatrix();
    if (!camera_from_imu) {
      spdlog::warn(
          "{}: /tf_static does not link the camera's frame '{}' to the IMU's '{}': camera-IMU rotation unknown", path,
          camera, imu);
    }
  }
  if (roles.pose < 0) {
    *poses_from_gps = roles.gps >= 0 && roles.imu >= 0 && first.imu.orientation.has_value();
    if (!*poses_from_gps) return;
    // No pose topic: the GPS fixes and the IMU's attitude give the IMU's pose.
    *body_from_camera = tree.Rotation(imu, camera);
    if (!*body_from_camera) {
      spdlog::warn(
          "{}: /tf_static does not link the IMU's frame '{}' to the camera's '{}': no poses from GPS and "
          "the IMU's attitude",
          path, imu, camera);
      *poses_from_gps = false;
      return;
    }
    spdlog::info("{}: camera poses from {} and the attitude of {}", path, bag.topics()[roles.gps].name,
                 bag.topics()[roles.imu].name);
    info->has_poses = true;
    info->pose_source = kPosesFromGps;
    info->body_from_camera = (*body_from_camera)->toRotationMatrix();
    return;
  }
  // Odometry names the frame it moves; a stamped pose is taken for the IMU's frame when the tree links it to
  // the camera, else for the camera's own.
  const bool odometry = rosmsg::KindOfType(bag.topics()[roles.pose].type) == MessageKind::kOdometry;
  const std::string& body = odometry ? first.pose.child_frame : imu;
  *body_from_camera = tree.Rotation(body, camera);
  if (!*body_from_camera) {
    spdlog::warn(
        "{}, topic {}: /tf_static does not link the pose's frame '{}' to the camera's '{}': the poses are "
        "taken for the camera's own",
        path, bag.topics()[roles.pose].name, body, camera);
  }
  info->body_from_camera = body_from_camera->value_or(Eigen::Quaterniond::Identity()).toRotationMatrix();
}

// The camera's intrinsics, and the stereo pair's calibration when a right camera was chosen.
void SetCalibration(const BagFile& bag, const std::string& path, const BagRoles& roles, const FirstMessages& first,
                    LogInfo* info) {
  if (first.has_camera_info) {
    const CameraIntrinsics camera = IntrinsicsOf(first.camera_info);
    if (camera.valid()) info->camera = camera;
    if (!camera.valid()) {
      spdlog::warn("{}, topic {}: camera info without intrinsics", path, bag.topics()[roles.camera_info].name);
    }
    // image_proc's undistorted images (image_rect, image_rect_color) come with the raw camera's info.
    const bool rectified = bag.topics()[roles.camera].name.find("image_rect") != std::string::npos;
    const Status lens = rectified ? Status::Ok() : DistortionOf(first.camera_info, &info->camera_distortion);
    if (!lens.ok()) {
      info->camera_distortion = Distortion{};
      spdlog::warn("{}, topic {}: {}; route frames are matched as undistorted", path,
                   bag.topics()[roles.camera_info].name, lens.message());
    }
  }
  if (roles.right < 0) return;
  StereoCalibration pair;
  const Status status = !first.has_camera_info || !first.has_right_info
                            ? Status::NotFound(
                                  "no camera info for both cameras (the right one's is expected beside its "
                                  "images, e.g. /cam1/camera_info)")
                            : StereoFromCameraInfo(first.camera_info, first.right_info, &pair);
  if (status.ok()) {
    info->stereo = pair;
    info->has_stereo = true;
  } else {
    spdlog::warn("{}, topic {}: {}; the stereo pair is not used", path, bag.topics()[roles.right].name,
                 status.message());
  }
}

// What the bag says before its frames: intrinsics, the frame rate and count, the rotations between sensors.
Status ReadLogInfo(BagFile* bag, const std::string& path, const BagRoles& roles, LogInfo* info,
                   std::optional<Eigen::Quaterniond>* body_from_camera, bool* poses_from_gps) {
  FirstMessages first;
  PATROLMAP_RETURN_IF_ERROR(ReadFirstMessages(bag, path, roles, &first));
  FrameTree tree;
  PATROLMAP_RETURN_IF_ERROR(ReadFrameTree(bag, path, roles.transforms, &tree));
  SetRotations(*bag, path, roles, first, tree, info, body_from_camera, poses_from_gps);
  SetCalibration(*bag, path, roles, first, info);
  info->has_depth = roles.depth >= 0;
  std::vector<TimestampNs> times;
  PATROLMAP_RETURN_IF_ERROR(bag->Times(roles.camera, &times));
  info->frame_count = static_cast<std::int64_t>(times.size());
  info->frame_rate_hz = MedianRate(times);
  info->timing = "header stamps of " + bag->topics()[roles.camera].name;
  info->has_imu = roles.imu >= 0;
  info->has_poses = info->has_poses || roles.pose >= 0;
  if (roles.pose >= 0) info->pose_source = kPosesFromTopic;
  info->has_speed = roles.pose >= 0 && rosmsg::KindOfType(bag->topics()[roles.pose].type) == MessageKind::kOdometry;
  return Status::Ok();
}

}  // namespace

bool IsBag(const std::string& path) {
  const fs::path location(path);
  if (location.extension() == ".bag" || location.extension() == ".db3") return true;
  std::error_code error;
  return fs::is_directory(location, error) && fs::is_regular_file(location / "metadata.yaml", error);
}

Status ListBagTopics(const std::string& path, std::vector<BagTopic>* topics) {
  std::unique_ptr<BagFile> bag;
  PATROLMAP_RETURN_IF_ERROR(OpenBagFile(path, &bag));
  *topics = bag->topics();
  for (std::size_t i = 0; i < topics->size(); ++i) {
    std::vector<TimestampNs> times;
    PATROLMAP_RETURN_IF_ERROR(bag->Times(static_cast<int>(i), &times));
    (*topics)[i].rate_hz = times.size() >= 2 ? MedianRate(times) : 0.0;
  }
  return Status::Ok();
}

Status OpenBag(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source) {
  std::unique_ptr<BagFile> bag;
  PATROLMAP_RETURN_IF_ERROR(OpenBagFile(path, &bag));
  BagRoles roles;
  PATROLMAP_RETURN_IF_ERROR(ChooseRoles(path, bag->topics(), options.topics, &roles));
  LogInfo info;
  info.path = path;
  info.kind = bag->wire() == rosmsg::Wire::kRos1 ? "ros1-bag" : "ros2-bag";
  info.flight_id = CleanFlightId(fs::path(path).lexically_normal().stem().string());
  if (info.flight_id.empty()) info.flight_id = CleanFlightId(fs::path(path).parent_path().filename().string());
  std::optional<Eigen::Quaterniond> body_from_camera;
  bool poses_from_gps = false;
  PATROLMAP_RETURN_IF_ERROR(ReadLogInfo(bag.get(), path, roles, &info, &body_from_camera, &poses_from_gps));
  if (options.frame_rate_hz > 0.0) {
    spdlog::warn("{}: --fps is for logs without times; a bag's frames keep their header stamps", path);
  }
  std::vector<int> topics = {roles.camera};
  for (int topic : {roles.imu, roles.gps, roles.pose, roles.depth, roles.right}) {
    if (topic >= 0) topics.push_back(topic);
  }
  std::unique_ptr<BagStream> stream;
  PATROLMAP_RETURN_IF_ERROR(bag->Stream(topics, 0, &stream));
  std::string used = "camera " + bag->topics()[roles.camera].name;
  const std::array<std::pair<const char*, int>, 5> others = {
      {{"imu", roles.imu}, {"gps", roles.gps}, {"pose", roles.pose}, {"depth", roles.depth}, {"right", roles.right}}};
  for (const auto& [role, topic] : others) {
    if (topic >= 0) used += std::string(", ") + role + " " + bag->topics()[topic].name;
  }
  spdlog::info("{}: {}", path, used);
  *source = std::make_unique<BagSource>(std::move(info), std::move(bag), roles, std::move(stream), body_from_camera,
                                        poses_from_gps);
  return Status::Ok();
}

}  // namespace patrolmap::io
