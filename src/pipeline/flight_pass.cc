#include "patrolmap/pipeline/flight_pass.h"
#include "patrolmap/core/words.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "patrolmap/core/option_check.h"
#include "patrolmap/pipeline/change_events.h"

namespace patrolmap::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Processed frames the ring holds: ring_s at the detector's processing rate, at least 1 (none when every
// N-th frame is a node: it is handed on at once).
std::size_t RingFrames(const FlightPassOptions& options, const flow::FrameTiming& timing) {
  if (options.node_every > 0) return 1;
  return static_cast<std::size_t>(std::max(1.0, std::ceil(options.ring_s * timing.processed_rate_hz)));
}

}  // namespace

bool FlightPassOptions::IsValid(std::string* error) const {
  return OptionCheck(error)
      .InRange("queue (--queue)", queue_capacity, 1, 1000)
      .AboveAtMost("ring (--ring-s)", ring_s, 0.0, 3600.0)
      .InRange("node_every", node_every, 0, 1000000)
      .ok();
}

FlightPass::FlightPass(const Config& config, const io::LogInfo& info, place::PlaceRecognizer* recognizer,
                       MapResult* places, const FlightPassOptions& options, ChangeMonitor* monitor)
    : options_(options),
      info_(info),
      detector_(config.flow, {info.camera, info.camera_from_imu, info.frame_rate_hz}),
      ring_(RingFrames(options, detector_.timing())),
      scale_(config.flow.frames.scale),
      monitor_(monitor),
      places_(recognizer, places),
      recorder_(config, info),
      place_queue_([this](KeyFrameInput&& input) { return AddPlace(std::move(input)); }, options.workers,
                   options.queue_capacity),
      change_queue_([this](ChangeWork&& work) { return AddChange(std::move(work)); }, options.workers,
                    options.queue_capacity) {}

FlightPass::~FlightPass() {
  place_queue_.Close();
  change_queue_.Close();
}

bool FlightPass::NeedsImage() const { return options_.node_every > 0 || detector_.NeedsImage(); }

Status FlightPass::AddFrame(const Frame& frame) {
  ++stats_.frames;
  yaw_.Add(frame.imu);
  PATROLMAP_RETURN_IF_ERROR(HandChanges(frame));
  if (options_.node_every > 0) {
    if (frame.image.empty() || readable_frames_++ % options_.node_every != 0) return Status::Ok();
    cv::Mat image = frame.image;
    if (scale_ < 1.0) cv::resize(frame.image, image, cv::Size(), scale_, scale_, cv::INTER_AREA);
    Remember(frame, image);
    return HandSlot(ring_[0]);
  }
  const bool processed = detector_.NeedsImage();
  const Clock::time_point start = Clock::now();
  detector_.Process(frame, &output_);
  if (processed) {
    const double seconds = SecondsSince(start);
    ++stats_.processed;
    stats_.flow_seconds += seconds;
    stats_.max_flow_seconds = std::max(stats_.max_flow_seconds, seconds);
    Remember(frame, detector_.last_image());
  }
  // Only the key locations are kept unless asked: memory stays bounded over hours.
  if (options_.keep_samples) samples_.insert(samples_.end(), output_.samples.begin(), output_.samples.end());
  output_.samples.clear();
  for (const KeyLocation& key_location : output_.key_locations)
    PATROLMAP_RETURN_IF_ERROR(HandKeyLocation(key_location));
  output_.key_locations.clear();
  if (place_queue_.failed()) return place_queue_.Close();
  return Status::Ok();
}

// The change stage's work for the frame: collected here, done on its queue.
Status FlightPass::HandChanges(const Frame& frame) {
  work_.clear();
  recorder_.Collect(frame, &work_);
  for (ChangeWork& work : work_) PATROLMAP_RETURN_IF_ERROR(change_queue_.Push(std::move(work)));
  return Status::Ok();
}

// Keeps the frame's image (at the flow scale, where the key frame is described) in the ring, reusing the
// slot's buffer.
void FlightPass::Remember(const Frame& frame, const cv::Mat& image) {
  Slot& slot = ring_[next_slot_];
  next_slot_ = (next_slot_ + 1) % ring_.size();
  slot.frame_index = frame.index;
  slot.timestamp_ns = frame.timestamp_ns;
  image.copyTo(slot.image);
  slot.heading = yaw_.yaw();
  slot.gps = frame.gps;
  slot.pose = frame.pose;
}

Status FlightPass::HandKeyLocation(const KeyLocation& key_location) {
  key_locations_.push_back(key_location);
  const auto slot = std::find_if(ring_.begin(), ring_.end(),
                                 [&](const Slot& s) { return s.frame_index == key_location.frame_index; });
  if (slot == ring_.end()) {
    ++stats_.lost_key_frames;
    return Status::Ok();
  }
  return HandSlot(*slot);
}

Status FlightPass::HandSlot(const Slot& slot) {
  work_.clear();
  recorder_.CollectKeyFrame(slot.timestamp_ns, slot.frame_index, slot.image, slot.pose, slot.gps, &work_);
  for (ChangeWork& work : work_) PATROLMAP_RETURN_IF_ERROR(change_queue_.Push(std::move(work)));
  KeyFrameInput input;
  input.key_frame.flight = info_.flight_id;
  input.key_frame.timed = info_.timed;
  input.key_frame.timestamp_ns = slot.timestamp_ns;
  input.key_frame.frame_index = slot.frame_index;
  input.key_frame.image = slot.image.clone();  // the slot is reused; the queue keeps its own copy
  feature_width_ = slot.image.cols;
  input.heading = slot.heading;
  input.gps = slot.gps;
  input.pose = slot.pose;
  ++stats_.key_frames;
  return place_queue_.Push(std::move(input));
}

// Place stage (its queue's thread): the node and its loop closure, then the monitor.
Status FlightPass::AddPlace(KeyFrameInput&& input) {
  const std::size_t closures = places_.result().loop_closures.size();
  PATROLMAP_RETURN_IF_ERROR(places_.Add(input));
  if (monitor_ == nullptr) return Status::Ok();
  const MapResult& result = places_.result();
  const MapLoopClosure* closure = result.loop_closures.size() > closures ? &result.loop_closures.back() : nullptr;
  monitor_->OnNode(result.nodes.back(), input.key_frame.image.cols, input.pose, closure, info_);
  return Status::Ok();
}

// Change stage (its queue's thread).
Status FlightPass::AddChange(ChangeWork&& work) {
  recorder_.Apply(work);
  if (monitor_ != nullptr) monitor_->OnChangeStep(work.timestamp_ns, recorder_);
  return Status::Ok();
}

Status FlightPass::Finish(FlightResult* result) {
  *result = FlightResult();
  if (options_.node_every == 0) {
    detector_.Finish(&output_);
    if (options_.keep_samples) samples_.insert(samples_.end(), output_.samples.begin(), output_.samples.end());
    for (const KeyLocation& key_location : output_.key_locations) {
      PATROLMAP_RETURN_IF_ERROR(HandKeyLocation(key_location));
    }
    output_ = flow::DetectorOutput();
  }
  work_.clear();
  recorder_.CollectRest(&work_);
  for (ChangeWork& work : work_) PATROLMAP_RETURN_IF_ERROR(change_queue_.Push(std::move(work)));
  PATROLMAP_RETURN_IF_ERROR(place_queue_.Close());
  PATROLMAP_RETURN_IF_ERROR(change_queue_.Close());
  recorder_.Finish(&result->record, &result->record_stats);
  result->record.feature_image_width = feature_width_;
  stats_.place_queue = place_queue_.stats();
  stats_.change_queue = change_queue_.stats();
  result->stats = stats_;
  DetectionResult& detection = result->detection;
  detection.samples = std::move(samples_);
  detection.key_locations = std::move(key_locations_);
  detection.frames_read = stats_.frames;
  detection.derotated = detector_.derotating();
  detection.timing = detector_.timing();
  detection.unusable_frames = detector_.unusable_frames();
  return Status::Ok();
}

Status Drive(io::FrameSource* source, FlightPass* pass, const DriveOptions& options, DriveResult* result) {
  const Clock::time_point start = Clock::now();
  Clock::time_point last_report = start;
  *result = DriveResult();
  Frame frame;
  Status status;
  std::optional<TimestampNs> first_ns;
  const auto stopped = [&options] { return options.stop != nullptr && options.stop->load(); };
  const auto next = [&] {
    source->KeepColour(pass->WantsColour());  // the route strip keeps a colour frame where the log has colour
    return source->Next(pass->NeedsImage(), &frame);
  };
  while (!stopped() && (status = next()).ok()) {
    if (!first_ns) first_ns = frame.timestamp_ns;
    const double flight_s = NsToSeconds(frame.timestamp_ns - *first_ns);
    if (options.max_seconds > 0.0 && flight_s > options.max_seconds) break;
    const Clock::time_point due =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(flight_s));
    if (options.paced) std::this_thread::sleep_until(due);
    PATROLMAP_RETURN_IF_ERROR(pass->AddFrame(frame));
    if (options.progress && pass->stats().frames % 50 == 0) {
      options.progress(pass->stats().frames, source->info().frame_count);
    }
    if (options.paced) result->max_lag_seconds = std::max(result->max_lag_seconds, SecondsSince(due) * 1.0);
    if (options.report && Clock::now() - last_report > std::chrono::seconds(5)) {
      last_report = Clock::now();
      options.report(pass->stats(), flight_s);
    }
  }
  result->interrupted = stopped();
  result->seconds = SecondsSince(start);
  if (options.progress) options.progress(pass->stats().frames, source->info().frame_count);
  return status.ok() || status.end_of_stream() ? Status::Ok() : status;
}

namespace {

std::vector<std::string> FlightWarnings(const io::LogInfo& info, const Config& config, const FlightPassOptions& options,
                                        const FlightResult& result) {
  std::vector<std::string> warnings;
  if (options.node_every == 0 && options.keep_samples)
    warnings = DetectionWarnings(info, result.detection, config.flow);
  const bool change_data = info.has_detections || info.has_depth || info.has_stereo;
  if (change_data && !info.has_poses) {
    warnings.push_back(info.path +
                       ": no camera poses (state_groundtruth_estimate0/data.csv; --poses FILE, a TUM or KITTI pose "
                       "file; or gps0/ with the IMU's attitude in imu0/data.csv), so its detections and depth are "
                       "not used: appearance change only");
  } else if (change_data && !info.camera) {
    warnings.push_back(info.path +
                       ": no camera intrinsics (cam0/sensor.yaml; --camera FILE), so its detections and depth are not "
                       "used: appearance change only");
  } else if (info.has_poses && !info.camera) {
    warnings.push_back(info.path +
                       ": camera poses but no camera intrinsics (cam0/sensor.yaml; --camera FILE), so its route "
                       "frames get no depth: appearance change from brightness only");
  }
  if (result.stats.lost_key_frames > 0) {
    warnings.push_back(info.path + ": " +
                       Counted(result.stats.lost_key_frames, "key location was", "key locations were") +
                       " confirmed after their frame left the ring of recent frames and are "
                       "not in the map; raise the ring (--ring-s)");
  }
  if (result.record_stats.forgotten_objects > 0) {
    warnings.push_back(info.path + ": the object map reached change.object_map.max_objects; " +
                       std::to_string(result.record_stats.forgotten_objects) +
                       " objects seen longest ago (unconfirmed ones first) were forgotten");
  }
  const PatrolRecordStats& grid = result.record_stats;
  if (grid.evicted_voxels > 0 || grid.dropped_voxel_updates > 0) {
    warnings.push_back(info.path + ": the evidence grid reached change.grid.memory_mb; " +
                       std::to_string(grid.evicted_voxels) + " least recently observed voxels and " +
                       std::to_string(grid.dropped_voxel_updates) +
                       " updates were dropped (no geometry change can be found there; raise change.grid.memory_mb)");
  }
  return warnings;
}

}  // namespace

Status RunFlight(io::FrameSource* source, const Config& config, const FlightPassOptions& options,
                 const DriveOptions& drive, place::PlaceRecognizer* recognizer, MapResult* places,
                 ChangeMonitor* monitor, FlightRun* run) {
  const io::LogInfo& info = source->info();
  const std::size_t nodes_before = places->nodes.size();
  {
    FlightPass pass(config, info, recognizer, places, options, monitor);
    PATROLMAP_RETURN_IF_ERROR(Drive(source, &pass, drive, &run->drive));
    PATROLMAP_RETURN_IF_ERROR(pass.Finish(&run->result));
  }
  FlightResult& result = run->result;
  result.detection.skipped = source->skipped();
  result.detection.seconds = run->drive.seconds;
  const bool none = options.node_every > 0 ? places->nodes.size() == nodes_before : result.stats.processed == 0;
  if (none && !run->drive.interrupted) return Status::DataLoss(info.path + ": no frame could be read");
  run->warnings = FlightWarnings(info, config, options, result);
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
