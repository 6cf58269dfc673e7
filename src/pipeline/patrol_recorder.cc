#include "patrolmap/pipeline/patrol_recorder.h"

#include <chrono>
#include <limits>

#include <spdlog/spdlog.h>

namespace patrolmap::pipeline {
namespace {

constexpr double kViewRateHz = 5.0;  // views kept for visibility

void SampleViews(const std::vector<CameraPoseSample>& poses, std::vector<CameraPoseSample>* views) {
  const TimestampNs step = SecondsToNs(1.0 / kViewRateHz);
  TimestampNs next = std::numeric_limits<TimestampNs>::min();
  for (const CameraPoseSample& pose : poses) {
    if (pose.timestamp_ns < next) continue;
    views->push_back(pose);
    next = pose.timestamp_ns + step;
  }
}

}  // namespace

PatrolRecorder::PatrolRecorder(const Config& config, io::PatrolSensors sensors)
    : config_(config),
      sensors_(std::move(sensors)),
      mapper_(config.change.object_map, sensors_.camera.value_or(CameraIntrinsics())),
      grid_(config.change.grid),
      next_grid_ns_(std::numeric_limits<TimestampNs>::min()) {
  base_.flight = sensors_.flight_id;
  if (sensors_.camera) base_.camera = *sensors_.camera;
  if (sensors_.poses.empty() || !sensors_.camera) return;
  SampleViews(sensors_.poses, &base_.views);
  base_.has_objects = !sensors_.detections.empty();
  active_ = base_.has_objects || !sensors_.depth.empty();
  stats_.detections = static_cast<int>(sensors_.detections.size());
}

void PatrolRecorder::CollectDepth(TimestampNs until_ns, std::vector<ChangeWork>* work) {
  const std::vector<io::DepthEntry>& depth = sensors_.depth;
  for (; next_depth_ < depth.size() && depth[next_depth_].timestamp_ns <= until_ns; ++next_depth_) {
    ChangeWork step;
    step.kind = ChangeWork::Kind::kGrid;
    step.timestamp_ns = depth[next_depth_].timestamp_ns;
    step.pose = io::PoseAt(sensors_.poses, step.timestamp_ns);
    step.depth_path = depth[next_depth_].path;
    work->push_back(std::move(step));
  }
}

void PatrolRecorder::Collect(const Frame& frame, std::vector<ChangeWork>* work) {
  if (!active_) return;
  CollectDepth(frame.timestamp_ns, work);
  const std::vector<io::DepthEntry>& depth = sensors_.depth;
  // Detections between frames belong to none and are dropped; those at the frame's time are its own.
  const std::vector<ObjectObservation>& all = sensors_.detections;
  while (next_detection_ < all.size() && all[next_detection_].timestamp_ns < frame.timestamp_ns) ++next_detection_;
  if (next_detection_ == all.size() || all[next_detection_].timestamp_ns != frame.timestamp_ns) return;
  ChangeWork step;
  step.kind = ChangeWork::Kind::kObjects;
  step.timestamp_ns = frame.timestamp_ns;
  while (next_detection_ < all.size() && all[next_detection_].timestamp_ns == frame.timestamp_ns) {
    step.detections.push_back(all[next_detection_++]);
  }
  step.pose = io::PoseAt(sensors_.poses, frame.timestamp_ns);
  if (!step.pose) return;
  const auto at = std::lower_bound(depth.begin(), depth.end(), frame.timestamp_ns,
                                   [](const io::DepthEntry& e, TimestampNs t) { return e.timestamp_ns < t; });
  if (at != depth.end() && at->timestamp_ns == frame.timestamp_ns) step.depth_path = at->path;
  step.image = frame.image.clone();  // the source reuses its buffer
  work->push_back(std::move(step));
}

void PatrolRecorder::CollectRest(std::vector<ChangeWork>* work) {
  if (active_) CollectDepth(std::numeric_limits<TimestampNs>::max(), work);
}

bool PatrolRecorder::ReadDepth(const std::string& path, cv::Mat* depth) {
  const Status status = io::ReadDepthImage(path, depth);
  if (status.ok()) return true;
  spdlog::warn("{}; skipped", status.message());
  ++stats_.skipped_depth_frames;
  depth->release();
  return false;
}

void PatrolRecorder::Apply(const ChangeWork& work) {
  if (!work.pose) return;
  if (work.kind == ChangeWork::Kind::kObjects) {
    depth_.release();
    if (!work.depth_path.empty()) ReadDepth(work.depth_path, &depth_);
    mapper_.AddFrame(work.detections, *work.pose, depth_, work.image);
    return;
  }
  if (work.timestamp_ns < next_grid_ns_) return;  // change.grid.rate_hz
  const auto start = std::chrono::steady_clock::now();
  if (!ReadDepth(work.depth_path, &depth_)) return;
  if (depth_.cols != base_.camera.width || depth_.rows != base_.camera.height) {
    spdlog::warn("{}: depth image is {}x{}, the camera {}x{}; skipped", work.depth_path, depth_.cols, depth_.rows,
                 base_.camera.width, base_.camera.height);
    ++stats_.skipped_depth_frames;
    return;
  }
  grid_.Integrate(depth_, base_.camera, *work.pose);
  next_grid_ns_ = work.timestamp_ns + SecondsToNs(1.0 / config_.change.grid.rate_hz);
  ++stats_.depth_frames;
  stats_.grid_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

PatrolRecord PatrolRecorder::Snapshot(TimestampNs until_ns, bool with_grid) const {
  PatrolRecord record = base_;
  record.views.erase(std::find_if(record.views.begin(), record.views.end(),
                                  [until_ns](const CameraPoseSample& v) { return v.timestamp_ns > until_ns; }),
                     record.views.end());
  if (record.has_objects) record.objects = mapper_.Finish();
  if (with_grid && !sensors_.depth.empty()) record.grid = grid_.ToData();
  return record;
}

void PatrolRecorder::Finish(PatrolRecord* record, PatrolRecordStats* stats) {
  *record = base_;
  if (active_ && record->has_objects) record->objects = mapper_.Finish();
  if (active_ && !sensors_.depth.empty()) record->grid = grid_.ToData();
  stats_.associations = mapper_.associations();
  stats_.association_seconds = mapper_.association_seconds();
  stats_.skipped_detections = mapper_.skipped();
  stats_.dropped_voxel_updates = grid_.dropped_updates();
  stats_.evicted_voxels = grid_.evicted_voxels();
  *stats = stats_;
}

PatrolRecord CameraOnlyRecord(const io::LogInfo& info) {
  PatrolRecord record;
  record.flight = info.flight_id;
  if (info.camera) record.camera = *info.camera;
  return record;
}

}  // namespace patrolmap::pipeline
