#include "patrolmap/pipeline/patrol_recorder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <spdlog/spdlog.h>
#include <opencv2/imgcodecs.hpp>

namespace patrolmap::pipeline {
namespace {

constexpr double kViewRateHz = 5.0;  // views kept for visibility

// Says how far the stereo pair marks surfaces: beyond, a return's range error exceeds
// change.grid.max_hit_sigma_m, so it carves free space only and nothing there can show as a surface that came or went.
// With depth.stereo.fuse_frames, surfaces seen alike by every fused frame are marked farther.
void SayStereoReach(const std::string& path, const depth::StereoDepth& stereo, const depth::DepthFusion* fusion,
                    const Config& config) {
  const change::EvidenceGridOptions& grid = config.change.grid;
  const double marked = std::min(stereo.DepthWithin(grid.max_hit_sigma_m), grid.max_range_m);
  spdlog::info(
      "{}: depth from the stereo pair ({:.2f} m apart, focal length {:.0f} px): nothing nearer than {:.1f} m is "
      "matched (depth.stereo.num_disparities {}{}); surfaces are marked within {:.1f} m, where the range error for "
      "depth.stereo.disparity_sigma_px {} stays within change.grid.max_hit_sigma_m {} m; farther returns only "
      "carve free space",
      path, stereo.baseline_m(), stereo.focal_px(), stereo.NearestDepth(), config.depth.stereo.num_disparities,
      config.depth.stereo.near_pass ? ", near_pass on" : "", marked, config.depth.stereo.disparity_sigma_px,
      grid.max_hit_sigma_m);
  if (fusion == nullptr) return;
  const int views = config.depth.stereo.fuse_frames + 1;
  const double fused = std::min(stereo.DepthWithin(grid.max_hit_sigma_m / fusion->ErrorScale(views)), grid.max_range_m);
  spdlog::info("{}: with depth.stereo.fuse_frames {}, within {:.1f} m where all {} fused depth frames agree", path,
               views - 1, fused, views);
}

// Says how far depth from the flight marks surfaces, as SayStereoReach does for a rig of the baseline sought.
void SayFlightReach(const std::string& path, const depth::FlightDepth& flight, const Config& config) {
  const change::EvidenceGridOptions& grid = config.change.grid;
  const double baseline = config.depth.flight.baseline_m;
  const double marked = std::min(std::sqrt(grid.max_hit_sigma_m / flight.SigmaPerM2(baseline)), grid.max_range_m);
  spdlog::info(
      "{}: depth from the flight's own frames, each matched with an earlier one about {:.2f} m away across the optical "
      "axis (depth.flight.baseline_m): nothing nearer than {:.1f} m is matched ({} disparities, "
      "depth.flight.min_range_m {}); surfaces are marked within {:.1f} m",
      path, baseline, flight.NearestDepth(baseline), flight.DisparitiesFor(baseline), config.depth.flight.min_range_m,
      marked);
}

}  // namespace

PatrolRecorder::PatrolRecorder(const Config& config, const io::LogInfo& info)
    : next_view_ns_(std::numeric_limits<TimestampNs>::min()),
      stereo_gate_(std::min(config.depth.stereo.rate_hz, config.change.grid.rate_hz)),
      route_(config.change.route_frames),
      mapper_(config.change.object_map, info.camera.value_or(CameraIntrinsics())),
      grid_(config.change.grid),
      grid_gate_(config.change.grid.rate_hz) {
  base_.flight = info.flight_id;
  base_.timed = info.timed;
  if (info.has_poses) base_.pose_source = info.pose_source;
  if (info.camera) base_.camera = *info.camera;
  base_.distortion = info.camera_distortion;
  if (!info.has_poses || !info.camera) return;
  base_.has_objects = info.has_detections;
  ChooseDepth(config, info);
  active_ = base_.has_objects || has_depth_;
}

void PatrolRecorder::ChooseDepth(const Config& config, const io::LogInfo& info) {
  using depth::DepthSource;
  const DepthSource source = config.depth.source;
  const bool images = info.has_depth && (source == DepthSource::kAuto || source == DepthSource::kImages);
  const bool stereo = !images && info.has_stereo && (source == DepthSource::kAuto || source == DepthSource::kStereo);
  if (source == DepthSource::kImages && !info.has_depth && info.has_stereo) {
    spdlog::warn("{}: depth.source is images but the log has no depth0/ (it has a stereo pair): no depth", info.path);
  }
  if (source == DepthSource::kStereo && !info.has_stereo) {
    spdlog::warn("{}: depth.source is stereo but the log has no stereo pair (cam1/ with its sensor.yaml): no depth",
                 info.path);
  }
  if (stereo) {
    const Status status = depth::StereoDepth::Create(*info.stereo, config.depth.stereo, &stereo_);
    if (!status.ok()) spdlog::warn("{}: {}; no stereo depth", info.path, status.message());
  }
  const bool precise_poses = info.pose_source != kPosesFromGps;
  if (source == DepthSource::kFlight && !precise_poses) {
    spdlog::warn("{}: depth.source is flight but the camera poses come from GPS fixes, metres off: no depth",
                 info.path);
  }
  if (!images && stereo_ == nullptr && precise_poses &&
      (source == DepthSource::kAuto || source == DepthSource::kFlight)) {
    flight_ = std::make_unique<depth::FlightDepth>(depth::Lens(base_.camera, base_.distortion), config.depth.flight,
                                                   config.depth.stereo);
    SayFlightReach(info.path, *flight_, config);
  }
  const double sigma_per_m2 = stereo_ != nullptr   ? stereo_->RangeSigma(1.0)
                              : flight_ != nullptr ? flight_->SigmaPerM2(config.depth.flight.baseline_m)
                                                   : 0.0;
  if (stereo_ != nullptr || flight_ != nullptr) {
    const depth::FusionOptions fusion{config.depth.stereo.fuse_frames, config.depth.stereo.fuse_gate_sigmas,
                                      sigma_per_m2, config.depth.stereo.fuse_shared_variance};
    if (fusion.frames > 0) fusion_ = std::make_unique<depth::DepthFusion>(base_.camera, fusion);
  }
  if (stereo_ != nullptr) SayStereoReach(info.path, *stereo_, fusion_.get(), config);
  use_stereo_ = stereo_ != nullptr;
  use_flight_ = flight_ != nullptr;
  has_depth_ = images || use_stereo_ || use_flight_;
  base_.depth_source = images ? kDepthFromImages : use_stereo_ ? kDepthFromStereo : use_flight_ ? kDepthFromFlight : "";
}

void PatrolRecorder::Collect(const Frame& frame, std::vector<ChangeWork>* work) {
  frame_spacing_ns_ = frame.timestamp_ns - last_frame_ns_;
  last_frame_ns_ = frame.timestamp_ns;
  if (!frame.image.empty() && route_.Due(frame.timestamp_ns)) {
    PushRouteWork(frame.timestamp_ns, frame.index, frame.colour.empty() ? frame.image : frame.colour, frame.pose,
                  frame.gps, false, work);
  }
  if (!active_) return;
  const TimestampNs step = SecondsToNs(1.0 / kViewRateHz);
  for (const CameraPoseSample& pose : frame.poses) {
    if (pose.timestamp_ns < next_view_ns_) continue;
    pending_views_.push_back(pose);
    next_view_ns_ = pose.timestamp_ns + step;
  }
  const std::size_t first = work->size();
  if (use_flight_) PushFlightWork(frame, work);
  if (has_depth_ && !use_flight_) {
    for (const DepthSample& depth : frame.depth) {
      if (depth.stereo() != use_stereo_) continue;
      if (use_stereo_ && !stereo_gate_.Due(depth.timestamp_ns)) continue;
      if (use_stereo_) stereo_gate_.Take(depth.timestamp_ns);
      ChangeWork step_work;
      step_work.kind = ChangeWork::Kind::kGrid;
      step_work.timestamp_ns = depth.timestamp_ns;
      step_work.pose = depth.pose;
      step_work.depth_path = depth.path;
      step_work.right_path = depth.right_path;
      step_work.depth_image = depth.image;
      step_work.right_image = depth.right_image;
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
      if (!has_depth_ || depth.stereo() != use_stereo_ || depth.timestamp_ns != frame.timestamp_ns) continue;
      objects.depth_path = depth.path;
      objects.right_path = depth.right_path;
      objects.depth_image = depth.image;
      objects.right_image = depth.right_image;
    }
    objects.image = frame.image.clone();  // the source reuses its buffer
    work->push_back(std::move(objects));
  }
  if (work->size() > first) (*work)[first].views = std::move(pending_views_), pending_views_.clear();
}

void PatrolRecorder::PushFlightWork(const Frame& frame, std::vector<ChangeWork>* work) {
  if (frame.image.empty() || !frame.pose || !stereo_gate_.Due(frame.timestamp_ns)) return;
  stereo_gate_.Take(frame.timestamp_ns);
  ChangeWork step_work;
  step_work.kind = ChangeWork::Kind::kGrid;
  step_work.timestamp_ns = frame.timestamp_ns;
  step_work.pose = frame.pose;
  step_work.image = frame.image.clone();  // the source reuses its buffer
  work->push_back(std::move(step_work));
}

void PatrolRecorder::CollectKeyFrame(TimestampNs timestamp_ns, std::int64_t frame_index, const cv::Mat& image,
                                     const std::optional<CameraPoseSample>& pose,
                                     const std::optional<Eigen::Vector3d>& gps, std::vector<ChangeWork>* work) {
  if (!image.empty()) PushRouteWork(timestamp_ns, frame_index, image, pose, gps, true, work);
}

void PatrolRecorder::PushRouteWork(TimestampNs timestamp_ns, std::int64_t frame_index, const cv::Mat& image,
                                   const std::optional<CameraPoseSample>& pose,
                                   const std::optional<Eigen::Vector3d>& gps, bool key_frame,
                                   std::vector<ChangeWork>* work) {
  ChangeWork route;
  route.kind = ChangeWork::Kind::kRoute;
  route.timestamp_ns = timestamp_ns;
  route.frame_index = frame_index;
  route.pose = pose;
  route.gps = gps;
  route.key_frame = key_frame;
  route_.Scale(image, &route.image);
  work->push_back(std::move(route));
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

bool PatrolRecorder::ReadStereoDepth(const ChangeWork& work, cv::Mat* depth) {
  if (work.timestamp_ns == stereo_depth_ns_) {  // matched already for the grid or the object map
    stereo_depth_.copyTo(*depth);
    return true;
  }
  left_ = work.depth_image.empty() ? cv::imread(work.depth_path, cv::IMREAD_GRAYSCALE) : work.depth_image;
  right_ = work.right_image.empty() ? cv::imread(work.right_path, cv::IMREAD_GRAYSCALE) : work.right_image;
  const std::string& unreadable = left_.empty() ? work.depth_path : work.right_path;
  Status status = left_.empty() || right_.empty() ? Status::DataLoss(unreadable + ": missing or unreadable image")
                                                  : stereo_->Compute(left_, right_, &stereo_depth_);
  if (status.ok()) {
    ++stats_.stereo_pairs;
    stereo_depth_ns_ = work.timestamp_ns;
    stereo_depth_.copyTo(*depth);
    return true;
  }
  stereo_depth_ns_ = std::numeric_limits<TimestampNs>::min();
  spdlog::warn("{} and {}: {}; skipped", work.depth_path, work.right_path, status.message());
  ++stats_.skipped_depth_frames;
  depth->release();
  return false;
}

bool PatrolRecorder::FlightPairDepth(const ChangeWork& work, cv::Mat* depth, double* sigma_per_m2) {
  if (work.image.cols != base_.camera.width || work.image.rows != base_.camera.height) {
    spdlog::warn("frame at {} ns is {}x{}, the camera {}x{}: no depth from it", work.timestamp_ns, work.image.cols,
                 work.image.rows, base_.camera.width, base_.camera.height);
    ++stats_.skipped_depth_frames;
    return false;
  }
  if (flight_->Compute(work.image, *work.pose, depth, sigma_per_m2)) return ++stats_.flight_pairs, true;
  ++stats_.unpaired_frames;
  return false;
}

bool PatrolRecorder::ReadDepth(const ChangeWork& work, cv::Mat* depth) {
  if (!work.right_path.empty() || !work.right_image.empty()) return ReadStereoDepth(work, depth);
  if (!work.depth_image.empty()) {
    work.depth_image.copyTo(*depth);
    return true;
  }
  const Status status = io::ReadDepthImage(work.depth_path, depth);
  if (status.ok()) return true;
  spdlog::warn("{}; skipped", status.message());
  ++stats_.skipped_depth_frames;
  depth->release();
  return false;
}

void PatrolRecorder::AddRouteFrame(const ChangeWork& work) {
  RouteFrame frame;
  frame.timestamp_ns = work.timestamp_ns;
  frame.frame_index = work.frame_index;
  frame.pose = work.pose;
  if (work.gps) frame.gps = work.gps->head<2>();
  route_.Add(std::move(frame), work.image, work.key_frame);
}

void PatrolRecorder::Apply(const ChangeWork& work) {
  base_.views.insert(base_.views.end(), work.views.begin(), work.views.end());
  if (work.kind == ChangeWork::Kind::kRoute) return AddRouteFrame(work);
  if (!work.pose) return;
  if (work.kind == ChangeWork::Kind::kObjects) {
    stats_.detections += static_cast<int>(work.detections.size());
    depth_.release();
    if (!work.depth_path.empty() || !work.depth_image.empty()) ReadDepth(work, &depth_);
    mapper_.AddFrame(work.detections, *work.pose, depth_, work.image);
    return;
  }
  // Stereo pairs and the flight's frames were chosen as they came (Collect), depth images are chosen here.
  const bool chosen = use_stereo_ || use_flight_;
  if (!chosen && !grid_gate_.Due(work.timestamp_ns)) return;
  const auto start = std::chrono::steady_clock::now();
  double sigma_per_m2 = stereo_ != nullptr ? stereo_->RangeSigma(1.0) : 0.0;
  if (use_flight_ ? !FlightPairDepth(work, &depth_, &sigma_per_m2) : !ReadDepth(work, &depth_)) return;
  if (depth_.cols != base_.camera.width || depth_.rows != base_.camera.height) {
    spdlog::warn("{}: depth image is {}x{}, the camera {}x{}; skipped", work.depth_path, depth_.cols, depth_.rows,
                 base_.camera.width, base_.camera.height);
    ++stats_.skipped_depth_frames;
    return;
  }
  if (fusion_ != nullptr) fusion_->Fuse(*work.pose, grid_.RayStep(depth_.cols), &depth_, &error_scale_);
  grid_.Integrate(depth_, base_.camera, *work.pose, sigma_per_m2, error_scale_);
  if (!chosen) grid_gate_.Take(work.timestamp_ns);
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
  if (active_ && has_depth_) record->grid = grid_.TakeData();
  stats_.associations = mapper_.associations();
  stats_.association_seconds = mapper_.association_seconds();
  stats_.skipped_detections = mapper_.skipped();
  stats_.forgotten_objects = mapper_.forgotten();
  stats_.dropped_voxel_updates = grid_.dropped_updates();
  stats_.evicted_voxels = grid_.evicted_voxels();
  record->route = route_.Take();
  stats_.route_frames = static_cast<int>(record->route.size());
  stats_.route_thinnings = route_.thinnings();
  stats_.dropped_route_frames = route_.dropped();
  *stats = stats_;
}

PatrolRecord CameraOnlyRecord(const io::LogInfo& info) {
  PatrolRecord record;
  record.flight = info.flight_id;
  record.timed = info.timed;
  if (info.camera) record.camera = *info.camera;
  record.distortion = info.camera_distortion;
  return record;
}

}  // namespace patrolmap::pipeline
