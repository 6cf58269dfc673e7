// The patrol record of a flight, built frame by frame in the per-frame pass (DESIGN.md: io -> change): the
// object map from the detections at each frame (with the frame's image and depth), the evidence grid from
// the depth images at change.grid.rate_hz, and the views that say where the camera looked.
//
// The pass's frame thread calls Collect() for every frame: it picks the sensor samples that belong to the
// frame (cheap; no image is read). The change thread calls Apply() for each piece of work in the order it
// was collected: it reads depth images and updates the object map and the grid. One thread or two, the
// record is the same.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_map.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/status.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/pipeline/config.h"

namespace patrolmap::pipeline {

struct PatrolRecordStats {
  int detections = 0, associations = 0, skipped_detections = 0;
  double association_seconds = 0.0;
  int depth_frames = 0;
  int skipped_depth_frames = 0;  // unreadable or of the wrong size: reported and left out
  double grid_seconds = 0.0;
  long long dropped_voxel_updates = 0;
  long long evicted_voxels = 0;  // the grid's least recently observed voxels, dropped at its memory budget
};

// One step of the change stage: the detections of a frame, or one depth image for the grid.
struct ChangeWork {
  enum class Kind { kObjects, kGrid };
  Kind kind = Kind::kGrid;
  TimestampNs timestamp_ns = 0;
  std::optional<CameraPoseSample> pose;       // at timestamp_ns; none: the step is skipped
  std::vector<ObjectObservation> detections;  // kObjects
  std::string depth_path;                     // kGrid; kObjects: the frame's depth image, if any
  cv::Mat image;                              // kObjects: the frame at the camera's size
};

class PatrolRecorder {
 public:
  // `sensors` from io::ReadPatrolSensors. Without poses or a camera nothing but the camera is recorded.
  PatrolRecorder(const Config& config, io::PatrolSensors sensors);

  // Whether the record has anything to build (poses, a camera, and detections or depth).
  bool active() const { return active_; }
  // Whether the next frames may need their image (detections remain to be placed).
  bool WantsImages() const { return active_ && next_detection_ < sensors_.detections.size(); }

  // Frame thread: appends the work due at `frame` (its detections; depth images up to its time).
  void Collect(const Frame& frame, std::vector<ChangeWork>* work);
  // Frame thread, after the last frame: the depth images after it.
  void CollectRest(std::vector<ChangeWork>* work);

  // Change thread: one step, in the order collected. An unreadable depth image is reported, counted and
  // left out.
  void Apply(const ChangeWork& work);

  // Change thread: the record so far (objects, grid and the views up to `until_ns`), for change events.
  PatrolRecord Snapshot(TimestampNs until_ns, bool with_grid) const;

  // Change thread, after the last Apply(): the record and what it took.
  void Finish(PatrolRecord* record, PatrolRecordStats* stats);

 private:
  void CollectDepth(TimestampNs until_ns, std::vector<ChangeWork>* work);
  bool ReadDepth(const std::string& path, cv::Mat* depth);

  Config config_;
  io::PatrolSensors sensors_;
  bool active_ = false;
  PatrolRecord base_;  // flight, camera, views
  std::size_t next_detection_ = 0, next_depth_ = 0;
  // Change thread:
  change::ObjectMapper mapper_;
  change::EvidenceGrid grid_;
  TimestampNs next_grid_ns_;
  cv::Mat depth_;
  PatrolRecordStats stats_;
};

// The patrol record of a flight mapped without its log's sensors (no poses): its flight id and camera.
PatrolRecord CameraOnlyRecord(const io::LogInfo& info);

}  // namespace patrolmap::pipeline
