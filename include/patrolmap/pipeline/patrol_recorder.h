// The patrol record of a flight, built frame by frame in the per-frame pass (DESIGN.md: io -> change): the
// object map from the detections at each frame (with the frame's image and depth), the evidence grid from
// the depth images at change.grid.rate_hz, and the views that say where the camera looked.
//
// The pass's frame thread calls Collect() for every frame: it turns the samples the frame brings (poses,
// detections, depth images; io::FrameSource) into work (cheap; no depth image is read). The change thread calls Apply()
// for each piece of work in the order it was collected: it reads depth images and updates the object map and the grid.
// One thread or two, the record is the same.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_map.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/rate_gate.h"
#include "patrolmap/core/status.h"
#include "patrolmap/depth/fusion.h"
#include "patrolmap/depth/motion_stereo.h"
#include "patrolmap/depth/stereo.h"
#include "patrolmap/io/frame_source.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/route_strip.h"

namespace patrolmap::pipeline {

struct PatrolRecordStats {
  int detections = 0, associations = 0, skipped_detections = 0;
  int forgotten_objects = 0;  // dropped at change.object_map.max_objects
  double association_seconds = 0.0;
  int depth_frames = 0;
  int skipped_depth_frames = 0;  // unreadable or of the wrong size: reported and left out
  int stereo_pairs = 0;          // pairs matched, for the grid and the object map (once where both take a frame)
  int flight_pairs = 0;          // depth from the flight: frames matched with an earlier one
  int unpaired_frames = 0;       // ... frames no earlier one stood usably far from (the start, hovering, turning)
  double grid_seconds = 0.0;
  long long dropped_voxel_updates = 0;
  long long evicted_voxels = 0;        // the grid's least recently observed voxels, dropped at its memory budget
  int route_frames = 0;                // frames kept along the route (change.route_frames)
  int route_thinnings = 0;             // times the route strip reached its memory budget and halved
  long long dropped_route_frames = 0;  // key frames not kept: key frames alone filled the budget
};

// One step of the change stage: the detections of a frame, one depth image for the grid, or a frame for the
// route strip; each carries the views sampled since the previous step (kViews: those alone, at the end).
struct ChangeWork {
  enum class Kind { kObjects, kGrid, kViews, kRoute };
  Kind kind = Kind::kGrid;
  std::vector<CameraPoseSample> views;
  TimestampNs timestamp_ns = 0;
  std::optional<CameraPoseSample> pose;       // at timestamp_ns; none: the step is skipped
  std::vector<ObjectObservation> detections;  // kObjects
  std::string depth_path;                     // kGrid; kObjects: the frame's depth image, if any; stereo: left
  std::string right_path;                     // stereo: the right image of the pair
  cv::Mat depth_image, right_image;           // instead of the paths: the images a bag handed over (DepthSample)
  cv::Mat image;                 // kObjects and kGrid from the flight: the frame at the camera's size; kRoute: scaled
  std::int64_t frame_index = 0;  // kRoute
  std::optional<Eigen::Vector3d> gps;  // kRoute: latitude, longitude, altitude, when the log has GPS
  bool key_frame = false;              // kRoute: the frame is a node's key frame
};

class PatrolRecorder {
 public:
  // For the log `info` describes. Without poses or a camera nothing but the camera is recorded.
  PatrolRecorder(const Config& config, const io::LogInfo& info);

  // Whether the record has anything to build (poses, a camera, and detections or depth).
  bool active() const { return active_; }

  // Frame thread: whether the next frame's colour image is wanted (for the route strip).
  bool WantsColour() const { return route_.DueSoon(last_frame_ns_, frame_spacing_ns_); }
  // Frame thread: appends the work `frame` brings (its detections; its depth images) and the views it adds.
  void Collect(const Frame& frame, std::vector<ChangeWork>* work);
  // Frame thread: a node's key frame for the route strip (its image at any scale, its pose and GPS if any).
  void CollectKeyFrame(TimestampNs timestamp_ns, std::int64_t frame_index, const cv::Mat& image,
                       const std::optional<CameraPoseSample>& pose, const std::optional<Eigen::Vector3d>& gps,
                       std::vector<ChangeWork>* work);
  // Frame thread, after the last frame: the views not yet handed on.
  void CollectRest(std::vector<ChangeWork>* work);

  // Change thread: one step, in the order collected. An unreadable depth image is reported, counted and
  // left out.
  void Apply(const ChangeWork& work);

  // Change thread: the record so far (objects and the views up to `until_ns`; the grid when `with_grid`), for
  // change events.
  PatrolRecord Snapshot(TimestampNs until_ns, bool with_grid) const;
  // Change thread: the evidence grid being built, read in place (change::DiffGrids); null without depth.
  const change::EvidenceGrid* grid() const { return has_depth_ ? &grid_ : nullptr; }

  // Change thread, after the last Apply(): the record and what it took.
  void Finish(PatrolRecord* record, PatrolRecordStats* stats);

 private:
  // Which depth the log gives the record (config.depth.source), and the stereo matcher it needs.
  void ChooseDepth(const Config& config, const io::LogInfo& info);
  bool ReadDepth(const ChangeWork& work, cv::Mat* depth);
  bool ReadStereoDepth(const ChangeWork& work, cv::Mat* depth);
  // Depth from the flight: `work`'s frame matched with an earlier one (FlightDepth), its range error per squared
  // metre into `sigma_per_m2`.
  bool FlightPairDepth(const ChangeWork& work, cv::Mat* depth, double* sigma_per_m2);
  // Frame thread: a frame for depth from the flight, at the pairs' rate.
  void PushFlightWork(const Frame& frame, std::vector<ChangeWork>* work);
  void AddRouteFrame(const ChangeWork& work);
  // Frame thread: a frame for the route strip, scaled, as work for the change thread.
  void PushRouteWork(TimestampNs timestamp_ns, std::int64_t frame_index, const cv::Mat& image,
                     const std::optional<CameraPoseSample>& pose, const std::optional<Eigen::Vector3d>& gps,
                     bool key_frame, std::vector<ChangeWork>* work);

  bool active_ = false;
  bool has_depth_ = false;
  bool use_stereo_ = false;  // depth from the stereo pair, not depth0/
  bool use_flight_ = false;  // depth from the flight's own frames
  PatrolRecord base_;        // flight, camera; views on the change thread
  // Frame thread:
  TimestampNs next_view_ns_;
  std::vector<CameraPoseSample> pending_views_;
  RateGate stereo_gate_;  // stereo pairs (and frames for depth from the flight) come with every frame: only those at
                          // the lower of depth.stereo.rate_hz and change.grid.rate_hz are work
  RouteStrip route_;      // Due() and Scale() on the frame thread, the rest on the change thread
  TimestampNs last_frame_ns_ = 0, frame_spacing_ns_ = 0;
  // Change thread:
  std::unique_ptr<depth::StereoDepth> stereo_;
  std::unique_ptr<depth::FlightDepth> flight_;
  std::unique_ptr<depth::DepthFusion> fusion_;  // depth.stereo.fuse_frames; none when 0
  cv::Mat error_scale_;                         // the fused range error's factor at each traced pixel (fusion_)
  cv::Mat left_, right_;
  // The last stereo depth and its frame's time: a frame the grid and the object map both take is matched once.
  cv::Mat stereo_depth_;
  TimestampNs stereo_depth_ns_ = std::numeric_limits<TimestampNs>::min();
  change::ObjectMapper mapper_;
  change::EvidenceGrid grid_;
  RateGate grid_gate_;  // depth images at change.grid.rate_hz
  cv::Mat depth_;
  PatrolRecordStats stats_;
};

// The patrol record of a flight mapped without its log's sensors (no poses): its flight id and camera.
PatrolRecord CameraOnlyRecord(const io::LogInfo& info);

}  // namespace patrolmap::pipeline
