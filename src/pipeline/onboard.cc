#include "patrolmap/pipeline/onboard.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "patrolmap/core/option_check.h"

namespace patrolmap::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Processed frames the ring holds: ring_s at the detector's processing rate, at least 1.
std::size_t RingFrames(const OnboardOptions& options, const flow::FrameTiming& timing) {
  return static_cast<std::size_t>(std::max(1.0, std::ceil(options.ring_s * timing.processed_rate_hz)));
}

}  // namespace

bool OnboardOptions::IsValid(std::string* error) const {
  return OptionCheck(error)
      .InRange("onboard queue (--queue)", queue_capacity, 1, 1000)
      .AboveAtMost("onboard ring (--ring-s)", ring_s, 0.0, 3600.0)
      .ok();
}

OnboardMapper::OnboardMapper(const Config& config, const io::LogInfo& info, place::PlaceRecognizer* recognizer,
                             const OnboardOptions& options)
    : options_(options),
      flight_(info.flight_id),
      detector_(config.flow, {info.camera, info.camera_from_imu, info.frame_rate_hz}),
      ring_(RingFrames(options, detector_.timing())),
      places_(recognizer, &places_result_) {
  if (options_.place_worker) worker_ = std::thread(&OnboardMapper::Work, this);
}

OnboardMapper::~OnboardMapper() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
}

Status OnboardMapper::AddFrame(const Frame& frame) {
  ++stats_.frames;
  yaw_.Add(frame.imu);
  const bool processed = detector_.NeedsImage();
  const Clock::time_point start = Clock::now();
  detector_.Process(frame, &output_);
  if (processed) {
    const double seconds = SecondsSince(start);
    ++stats_.processed;
    stats_.flow_seconds += seconds;
    stats_.max_flow_seconds = std::max(stats_.max_flow_seconds, seconds);
    Remember(frame);
  }
  output_.samples.clear();  // only the key locations are kept: memory stays bounded over hours
  for (const KeyLocation& key_location : output_.key_locations) PATROLMAP_RETURN_IF_ERROR(Hand(key_location));
  output_.key_locations.clear();
  return place_failed_.load() ? PlaceStatus() : Status::Ok();  // no lock per frame while all is well
}

// Keeps the processed frame's image (at the flow scale, as `patrolmap map` describes key frames) in the
// ring, reusing the slot's buffer.
void OnboardMapper::Remember(const Frame& frame) {
  Slot& slot = ring_[next_slot_];
  next_slot_ = (next_slot_ + 1) % ring_.size();
  slot.frame_index = frame.index;
  slot.timestamp_ns = frame.timestamp_ns;
  detector_.last_image().copyTo(slot.image);
  slot.heading = yaw_.yaw();
  slot.gps = frame.gps;
}

Status OnboardMapper::Hand(const KeyLocation& key_location) {
  key_locations_.push_back(key_location);
  const auto slot = std::find_if(ring_.begin(), ring_.end(),
                                 [&](const Slot& s) { return s.frame_index == key_location.frame_index; });
  if (slot == ring_.end()) {
    ++stats_.lost_key_frames;
    return Status::Ok();
  }
  KeyFrameInput input;
  input.key_frame.flight = flight_;
  input.key_frame.timestamp_ns = slot->timestamp_ns;
  input.key_frame.frame_index = slot->frame_index;
  input.key_frame.image = slot->image.clone();  // the slot is reused; the queue keeps its own copy
  input.heading = slot->heading;
  input.gps = slot->gps;
  ++stats_.key_frames;
  return Enqueue(std::move(input));
}

Status OnboardMapper::Enqueue(KeyFrameInput&& input) {
  if (!options_.place_worker) return places_.Add(input);
  const Clock::time_point start = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock,
                [this] { return static_cast<int>(queue_.size()) < options_.queue_capacity || !place_status_.ok(); });
  stats_.waited_seconds += SecondsSince(start);
  if (!place_status_.ok()) return place_status_;
  queue_.push_back(std::move(input));
  stats_.max_queue = std::max(stats_.max_queue, static_cast<int>(queue_.size()));
  lock.unlock();
  changed_.notify_all();
  return Status::Ok();
}

void OnboardMapper::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return !queue_.empty() || closing_; });
    if (queue_.empty()) return;  // closing, and nothing left
    KeyFrameInput input = std::move(queue_.front());
    lock.unlock();
    const Status status = places_.Add(input);  // only this thread touches the place stage
    lock.lock();
    queue_.pop_front();
    if (!status.ok() && place_status_.ok()) {
      place_status_ = status;
      place_failed_.store(true);
    }
    changed_.notify_all();
  }
}

Status OnboardMapper::PlaceStatus() {
  std::lock_guard<std::mutex> lock(mutex_);
  return place_status_;
}

Status OnboardMapper::Finish(MapResult* result) {
  detector_.Finish(&output_);
  for (const KeyLocation& key_location : output_.key_locations) PATROLMAP_RETURN_IF_ERROR(Hand(key_location));
  output_ = flow::DetectorOutput();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
  PATROLMAP_RETURN_IF_ERROR(PlaceStatus());
  result->nodes.insert(result->nodes.end(), places_result_.nodes.begin(), places_result_.nodes.end());
  result->loop_closures.insert(result->loop_closures.end(), places_result_.loop_closures.begin(),
                               places_result_.loop_closures.end());
  result->seconds_features += places_result_.seconds_features;
  result->seconds_query += places_result_.seconds_query;
  result->seconds_verify += places_result_.seconds_verify;
  result->seconds_add += places_result_.seconds_add;
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
