// Mapping in one pass over a live frame stream (DESIGN.md, front ends:
// patrolmap-onboard). The flow stage runs for every frame on the caller's
// thread; a key location the flow stage confirms is looked up in a ring of
// the recently processed frames (it is confirmed up to half a smoothing window
// and an extremum's fall later) and handed to the place stage through a
// bounded queue, on a worker thread or inline. The key frames, their order and
// so the map are the same either way, and the same as `patrolmap map` gives
// for the same log and configuration.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/io/frame_source.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/map.h"

namespace patrolmap::pipeline {

struct OnboardOptions {
  bool place_worker = true;  // place recognition on its own thread (false: inline, on the frame thread)
  int queue_capacity = 4;    // key frames waiting for the place stage; when full the frame thread waits
  // Time of recently processed frames kept for key locations confirmed late (a key location is confirmed
  // up to half a smoothing window and an extremum's fall after its frame) [s]. At the default 6 processed
  // frames per second 40 s is 240 frames, about 90 kB each at 376x240.
  double ring_s = 40.0;
  bool IsValid(std::string* error) const;
};

struct OnboardStats {
  std::int64_t frames = 0;        // frames given to AddFrame
  std::int64_t processed = 0;     // of which the flow stage processed
  int key_frames = 0;             // key locations handed to the place stage
  int lost_key_frames = 0;        // confirmed after their frame left the ring (not mapped)
  int max_queue = 0;              // deepest the queue got
  double flow_seconds = 0.0;      // flow stage, summed over processed frames
  double max_flow_seconds = 0.0;  // ... its slowest frame
  double waited_seconds = 0.0;    // the frame thread waiting for room in the queue
};

class OnboardMapper {
 public:
  // `recognizer` (may already hold earlier flights) is used by the place stage only, until Finish().
  OnboardMapper(const Config& config, const io::LogInfo& info, place::PlaceRecognizer* recognizer,
                const OnboardOptions& options);
  ~OnboardMapper();
  OnboardMapper(const OnboardMapper&) = delete;
  OnboardMapper& operator=(const OnboardMapper&) = delete;

  // Whether the flow stage will process the next frame (so a reader can skip decoding the others).
  bool NeedsImage() const { return detector_.NeedsImage(); }

  // Takes every frame in order. Fails when the place stage has failed (the error it gave).
  Status AddFrame(const Frame& frame);

  // Flushes the flow stage, lets the place stage finish the queue and moves the nodes and loop closures
  // into `result` (after those it held). Call once.
  Status Finish(MapResult* result);

  const OnboardStats& stats() const { return stats_; }
  const std::vector<KeyLocation>& key_locations() const { return key_locations_; }

 private:
  struct Slot {
    std::int64_t frame_index = -1;
    TimestampNs timestamp_ns = 0;
    cv::Mat image;
    double heading = 0.0;
    std::optional<Eigen::Vector3d> gps;
  };
  void Remember(const Frame& frame);
  Status Hand(const KeyLocation& key_location);
  Status Enqueue(KeyFrameInput&& input);
  void Work();
  Status PlaceStatus();

  OnboardOptions options_;
  std::string flight_;
  flow::KeyLocationDetector detector_;
  flow::DetectorOutput output_;
  YawIntegrator yaw_;
  std::vector<Slot> ring_;
  std::size_t next_slot_ = 0;
  std::vector<KeyLocation> key_locations_;
  OnboardStats stats_;

  MapResult places_result_;
  PlaceStage places_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<KeyFrameInput> queue_;
  bool closing_ = false;
  Status place_status_;
  std::atomic<bool> place_failed_{false};  // place_status_ holds an error
  std::thread worker_;
};

}  // namespace patrolmap::pipeline
