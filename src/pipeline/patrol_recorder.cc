#include "patrolmap/pipeline/patrol_recorder.h"

#include <chrono>
#include <limits>

#include <spdlog/spdlog.h>

namespace patrolmap::pipeline {
namespace {

constexpr double kViewRateHz = 5.0;  // views kept for visibility

}  // namespace

PatrolRecorder::PatrolRecorder(const Config& config, const io::LogInfo& info)
    : grid_step_ns_(SecondsToNs(1.0 / config.change.grid.rate_hz)),
      next_view_ns_(std::numeric_limits<TimestampNs>::min()),
      mapper_(config.change.object_map, info.camera.value_or(CameraIntrinsics())),
      grid_(config.change.grid),
      next_grid_ns_(std::numeric_limits<TimestampNs>::min()) {
  base_.flight = info.flight_id;
  if (info.camera) base_.camera = *info.camera;
  if (!info.has_poses || !info.camera) return;
  base_.has_objects = info.has_detections;
  has_depth_ = info.has_depth;
  active_ = base_.has_objects || has_depth_;
}

void PatrolRecorder::Collect(const Frame& frame, std::vector<ChangeWork>* work) {
  if (!active_) return;
  const TimestampNs step = SecondsToNs(1.0 / kViewRateHz);
  for (const CameraPoseSample& pose : frame.poses) {
    if (pose.timestamp_ns < next_view_ns_) continue;
    pending_views_.push_back(pose);
    next_view_ns_ = pose.timestamp_ns + step;
  }
  const std::size_t first = work->size();
  if (has_depth_) {
    for (const DepthSample& depth : frame.depth) {
      ChangeWork step_work;
      step_work.kind = ChangeWork::Kind::kGrid;
      step_work.timestamp_ns = depth.timestamp_ns;
      step_work.pose = depth.pose;
      step_work.depth_path = depth.path;
      work->push_back(std::move(step_work));
    }
  }
  if (base_.has_objects && !frame.detections.empty() && frame.pose) {
    ChangeWork objects;
    objects.kind = ChangeWork::Kind::kObjects;
    objects.timestamp_ns = frame.timestamp_ns;
    objects.detections = frame.detections;
    objects.pose = frame.pose;
    for (const DepthSample& depth : frame.depth) {
      if (depth.timestamp_ns == frame.timestamp_ns) objects.depth_path = depth.path;
    }
    objects.image = frame.image.clone();  // the source reuses its buffer
    work->push_back(std::move(objects));
  }
  if (work->size() > first) (*work)[first].views = std::move(pending_views_), pending_views_.clear();
}

void PatrolRecorder::CollectRest(std::vector<ChangeWork>* work) {
  if (pending_views_.empty()) return;
  ChangeWork views;
  views.kind = ChangeWork::Kind::kViews;
  views.timestamp_ns = pending_views_.back().timestamp_ns;
  views.views = std::move(pending_views_);
  pending_views_.clear();
  work->push_back(std::move(views));
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
  base_.views.insert(base_.views.end(), work.views.begin(), work.views.end());
  if (!work.pose) return;
  if (work.kind == ChangeWork::Kind::kObjects) {
    stats_.detections += static_cast<int>(work.detections.size());
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
  next_grid_ns_ = work.timestamp_ns + grid_step_ns_;
  ++stats_.depth_frames;
  stats_.grid_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

PatrolRecord PatrolRecorder::Snapshot(TimestampNs until_ns, bool with_grid) const {
  PatrolRecord record = base_;
  record.views.erase(std::find_if(record.views.begin(), record.views.end(),
                                  [until_ns](const CameraPoseSample& v) { return v.timestamp_ns > until_ns; }),
                     record.views.end());
  if (record.has_objects) record.objects = mapper_.Finish();
  if (with_grid && has_depth_) record.grid = grid_.ToData();
  return record;
}

void PatrolRecorder::Finish(PatrolRecord* record, PatrolRecordStats* stats) {
  *record = base_;
  if (active_ && record->has_objects) record->objects = mapper_.Finish();
  if (active_ && has_depth_) record->grid = grid_.ToData();
  stats_.associations = mapper_.associations();
  stats_.association_seconds = mapper_.association_seconds();
  stats_.skipped_detections = mapper_.skipped();
  stats_.forgotten_objects = mapper_.forgotten();
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
