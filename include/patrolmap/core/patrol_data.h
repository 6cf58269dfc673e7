// Value types of the change stage (DESIGN.md, change): what a log tells about
// where the camera was and what it saw, and what one patrol keeps of it (its
// object map, evidence grid and views) so that two patrols of a map can be
// compared without their logs. World frame: the log's state estimate frame,
// z up [m]. Camera frame: x right, y down, z forward.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include "patrolmap/core/types.h"

namespace patrolmap {

// The image box around `corners` seen from `pose` through `camera` and its lens (not clipped to the image); empty
// when any of them lies less than 0.1 m in front of the camera.
cv::Rect2d ProjectCorners(const CameraIntrinsics& camera, const CameraPoseSample& pose,
                          const std::array<Eigen::Vector3d, 8>& corners, const Distortion& distortion = {});

// One object of a patrol's object map (paper 000): detections associated
// across frames, with the label-confidence and label-count accumulators.
struct MapObject {
  int id = 0;
  std::string label;        // the label with the highest accumulated confidence
  double confidence = 0.0;  // mean confidence of the detections with that label
  int detections = 0;
  bool confirmed = true;  // seen often enough to count; unconfirmed ones only explain later sightings
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // world frame [m]
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();   // axis-aligned extent of its points (2nd to 98th
                                                       // percentile; without points: its mean detected size)
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3f> points;  // segmented points (voxel-filtered); empty without depth
  std::vector<float> descriptor;        // appearance, mean over its views: 8-bin gradient-orientation histogram, then
                                        // the brightness rank (share of the frame's pixels darker than it)
  double height = 0.0;                  // vertical extent of its points [m]; 0 without points
  struct LabelEvidence {
    std::string label;
    double confidence_sum = 0.0;
    int count = 0;
  };
  std::vector<LabelEvidence> labels;
  TimestampNs first_seen_ns = 0, last_seen_ns = 0;
  // The site object it is: one id for the same physical object across a map's patrols (change/site_objects.h);
  // -1 until numbered.
  int site_id = -1;
};

// Hit and pass counts of one voxel of an evidence grid (paper 004).
struct VoxelEvidence {
  std::int32_t x = 0, y = 0, z = 0;  // voxel index: centre = index * voxel_size
  std::uint16_t hits = 0;            // rays that ended in the voxel
  std::uint16_t passes = 0;          // rays that passed through it
};

// The order voxels are stored in: ascending (x, y, z).
inline bool VoxelBefore(const VoxelEvidence& a, const VoxelEvidence& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// An evidence grid as stored: its voxels in ascending (x, y, z) order.
struct EvidenceGridData {
  double voxel_size = 0.0;  // [m]; 0 when the patrol had no depth
  std::vector<VoxelEvidence> voxels;
  long long evicted_voxels = 0;  // dropped when the grid's memory budget was reached (oldest first)
};

// Calls visit(a_voxel, b_voxel) for every voxel both grids hold, in order (a merge of the sorted lists).
template <typename Visit>
void ForEachCommonVoxel(const EvidenceGridData& a, const EvidenceGridData& b, Visit visit) {
  auto i = a.voxels.begin(), j = b.voxels.begin();
  while (i != a.voxels.end() && j != b.voxels.end()) {
    if (VoxelBefore(*i, *j)) {
      ++i;
    } else if (VoxelBefore(*j, *i)) {
      ++j;
    } else {
      visit(*i++, *j++);
    }
  }
}

// One frame kept along a patrol's route (change.route_frames), for the pictures of the change report and
// the appearance comparison along the route: the grey frame as JPEG, at most max_width pixels wide.
struct RouteFrame {
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  std::optional<CameraPoseSample> pose;  // the camera pose at its time, when the log has poses
  std::optional<Eigen::Vector2d> gps;    // latitude, longitude [deg], when the log has GPS
  std::vector<unsigned char> jpeg;
};

// Where a patrol's camera poses came from (LogInfo and PatrolRecord::pose_source); empty without poses, and in
// maps written before format 9.
inline constexpr char kPosesFromStateEstimate[] = "state_estimate";  // state_groundtruth_estimate0/
inline constexpr char kPosesFromTopic[] = "pose_topic";              // a bag's pose or odometry topic
inline constexpr char kPosesFromFile[] = "pose_file";                // --poses FILE
inline constexpr char kPosesFromGps[] = "gps_attitude";              // GPS fixes and the IMU's attitude
inline bool KnownPoseSource(const std::string& source) {
  return source.empty() || source == kPosesFromStateEstimate || source == kPosesFromTopic || source == kPosesFromFile ||
         source == kPosesFromGps;
}

// Where a patrol's grid and object depth came from (PatrolRecord::depth_source); empty without depth.
inline constexpr char kDepthFromImages[] = "images";  // depth0/
inline constexpr char kDepthFromStereo[] = "stereo";  // the log's stereo pair
inline constexpr char kDepthFromFlight[] = "flight";  // motion stereo between the flight's own frames
inline bool KnownDepthSource(const std::string& source) {
  return source.empty() || source == kDepthFromImages || source == kDepthFromStereo || source == kDepthFromFlight;
}

// What a patrol (one flight of a map) keeps for change detection.
struct PatrolRecord {
  std::string flight;
  CameraIntrinsics camera;              // of the images the views and detections refer to
  Distortion distortion{};              // of the camera's lens; its raw images (route frames) keep it
  int feature_image_width = 0;          // width of the images its key-frame features were found in
  std::vector<CameraPoseSample> views;  // camera poses sampled along the flight
  bool has_objects = false;             // the log had detections
  std::vector<MapObject> objects;
  EvidenceGridData grid;          // voxel_size 0 when the log had no depth
  std::string depth_source;       // where the grid's and objects' depth came from: kDepthFrom...
  std::string pose_source;        // where its camera poses came from (kPosesFrom...; map format 9 on)
  std::vector<RouteFrame> route;  // in time order; key frames among them (map format 6 on)
  // Whether the log had timestamps (false: 'recent' nodes are counted in images; map format 7 on, true before),
  // so a merge recognises its nodes' places as the mapping run did.
  bool timed = true;
  // The log the patrol was read from, as an absolute path, and io::LogDigest of its content (map format 11 on;
  // empty before, and for a camera), so the same log is never mapped twice.
  std::string source, source_digest;
  // Read for a patrol (graph::LoadMap, PatrolDetail::kLatest): without its route frames, and with only the voxels of
  // its grid no later patrol observed; the file keeps the rest, and the next save carries it over.
  bool partial = false;
  // Kept as an archive once later patrols came (graph::MapRetention): the grid holds only the voxels no later patrol
  // observed, the route frames are thinned out. Map format 13 on.
  bool archived = false;
};

// The view of `record` nearest in time to `timestamp_ns`, when one lies within `tolerance_ns` of it.
std::optional<CameraPoseSample> ViewAt(const PatrolRecord& record, TimestampNs timestamp_ns, TimestampNs tolerance_ns);

}  // namespace patrolmap
