// The per-frame pass every front end drives (DESIGN.md, pipeline): `patrolmap map`, `patrolmap patrol` and
// `patrolmap-onboard` read a log once, frame by frame, through one FlightPass.
//
//   frame thread   FrameSource -> flow stage (key locations) -> ring of processed frames
//                                   | a key location, once confirmed, with its frame from the ring
//   place queue    -> place stage (node, loop closure)           [worker thread or inline]
//   change queue   -> patrol recorder (object map, evidence grid) [worker thread or inline]
//
// A key location is confirmed up to half a smoothing window and an extremum's fall after its frame, so the
// ring keeps the recently processed frames. Both queues are bounded; each stage handles its inputs in order,
// so nodes, loop closures, objects and voxels are the same whether the stages run on workers or inline.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/io/frame_source.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/pipeline/map.h"
#include "patrolmap/pipeline/patrol_recorder.h"
#include "patrolmap/pipeline/stage_queue.h"

namespace patrolmap::pipeline {

class ChangeMonitor;

struct FlightPassOptions {
  bool workers = true;     // place and change stages on their own threads (false: inline, on the frame thread)
  int queue_capacity = 4;  // inputs waiting for each stage; when full the frame thread waits
  // Time of recently processed frames kept for key locations confirmed late [s]. At the default 6 processed
  // frames per second 40 s is 240 frames, about 90 kB each at 376x240.
  double ring_s = 40.0;
  // 0: nodes at the flow stage's key locations; N: every N-th readable frame is a node (image collections,
  // place recognition alone; the flow stage does not run).
  int node_every = 0;
  bool keep_samples = false;  // keep the response of every processed frame (offline: the response plot)
  bool IsValid(std::string* error) const;
};

struct FlightPassStats {
  std::int64_t frames = 0;        // frames given to AddFrame
  std::int64_t processed = 0;     // of which the flow stage processed
  int key_frames = 0;             // key frames handed to the place stage
  int lost_key_frames = 0;        // confirmed after their frame left the ring (not mapped)
  double flow_seconds = 0.0;      // flow stage, summed over processed frames
  double max_flow_seconds = 0.0;  // ... its slowest frame
  StageQueueStats place_queue, change_queue;
};

// What one flight gives besides the nodes and loop closures (which go to the MapResult).
struct FlightResult {
  DetectionResult detection;  // key locations; samples when keep_samples; timing
  PatrolRecord record;        // objects, grid and views when the log has poses and detections or depth
  PatrolRecordStats record_stats;
  FlightPassStats stats;
};

class FlightPass {
 public:
  // `recognizer` (may already hold earlier flights) and `places` are used by the place stage only, until
  // Finish(); `monitor` (may be null) is told of key frames and of the record as it grows.
  FlightPass(const Config& config, const io::LogInfo& info, place::PlaceRecognizer* recognizer, MapResult* places,
             const FlightPassOptions& options, ChangeMonitor* monitor = nullptr);
  ~FlightPass();
  FlightPass(const FlightPass&) = delete;
  FlightPass& operator=(const FlightPass&) = delete;

  // Whether the next frame needs its image (so a reader can skip decoding the others).
  bool NeedsImage() const;
  // Whether the next frame's colour image is wanted (io::FrameSource::KeepColour).
  bool WantsColour() const { return recorder_.WantsColour(); }

  // Takes every frame in order. Fails when a stage has failed (the error it gave).
  Status AddFrame(const Frame& frame);

  // Flushes the flow stage, lets both stages finish their queues and fills `result`. Call once.
  Status Finish(FlightResult* result);

  const FlightPassStats& stats() const { return stats_; }

 private:
  struct Slot {
    std::int64_t frame_index = -1;
    TimestampNs timestamp_ns = 0;
    cv::Mat image;
    double heading = 0.0;
    std::optional<Eigen::Vector3d> gps;
    std::optional<CameraPoseSample> pose;
  };
  void Remember(const Frame& frame, const cv::Mat& image);
  Status HandKeyLocation(const KeyLocation& key_location);
  Status HandSlot(const Slot& slot);
  Status HandChanges(const Frame& frame);
  Status AddPlace(KeyFrameInput&& input);
  Status AddChange(ChangeWork&& work);

  FlightPassOptions options_;
  const io::LogInfo info_;
  flow::KeyLocationDetector detector_;
  flow::DetectorOutput output_;
  YawIntegrator yaw_;
  std::vector<Slot> ring_;
  std::size_t next_slot_ = 0;
  std::int64_t readable_frames_ = 0;
  double scale_;
  int feature_width_ = 0;  // of the images key frames are described in [pixels]
  FlightPassStats stats_;
  std::vector<KeyLocation> key_locations_;
  std::vector<FlowSample> samples_;
  std::vector<ChangeWork> work_;

  ChangeMonitor* monitor_;
  PlaceStage places_;
  PatrolRecorder recorder_;
  StageQueue<KeyFrameInput> place_queue_;  // after places_ and recorder_: its worker uses them
  StageQueue<ChangeWork> change_queue_;
};

// How a front end feeds a source to a pass.
struct DriveOptions {
  bool paced = false;                       // at the log's own rate (a live camera paces itself)
  double max_seconds = 0.0;                 // stop after this much of the flight; 0: the whole log
  const std::atomic<bool>* stop = nullptr;  // stop when it becomes true (a signal)
  std::function<void(const FlightPassStats&, double flight_s)> report;    // every few seconds
  std::function<void(std::int64_t frames, std::int64_t total)> progress;  // every 50 frames; total -1: unknown
};

struct DriveResult {
  double seconds = 0.0;          // wall time
  double max_lag_seconds = 0.0;  // paced: how far behind the log's clock the frame thread fell
  bool interrupted = false;      // stopped by `stop`
};

// Feeds `source` to `pass` until it ends, `max_seconds` of it have passed or a stop is requested. Fails
// when the source or a stage fails; an end of stream is success.
Status Drive(io::FrameSource* source, FlightPass* pass, const DriveOptions& options, DriveResult* result);

struct FlightRun {
  FlightResult result;
  DriveResult drive;
  std::vector<std::string> warnings;  // what the user should know, one sentence each, naming the log
};

// One flight through a FlightPass driven by `drive`: its nodes and loop closures go to `places` (after those
// of earlier flights), the rest to `run`. Fails when no frame could be read.
Status RunFlight(io::FrameSource* source, const Config& config, const FlightPassOptions& options,
                 const DriveOptions& drive, place::PlaceRecognizer* recognizer, MapResult* places,
                 ChangeMonitor* monitor, FlightRun* run);

}  // namespace patrolmap::pipeline
