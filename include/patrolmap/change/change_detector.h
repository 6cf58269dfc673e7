// The comparison of a patrol with one prior patrol (DESIGN.md: prior map -> ChangeDetector -> report and onboard
// events). `patrol` and `diff` compare a finished flight (Compare), patrolmap-onboard the record still being built
// while flying (Check); both by the same steps, written here once:
//   alignment   the whole-voxel shift of the current grid onto the prior's (grid_alignment.h)
//   geometry    the two evidence grids compared (evidence_grid.h); where their surfaces differ almost everywhere
//               the two flights' poses disagree, and nothing placed by those poses is compared
//   objects     the detected ones, the two object maps (object_diff.h), then the class-agnostic ones, clusters of
//               the changed space no detector named (geometry_objects.h)
//   appearance  at each loop closure between the patrols, their key frames (appearance.h); where both patrols
//               kept route frames, along the whole route instead (route_compare.h)
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/change_location.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/grid_alignment.h"
#include "patrolmap/change/options.h"
#include "patrolmap/change/report.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

// A key frame as the appearance comparison takes it: features found on an image `feature_width` pixels wide
// (0: on the thumbnail itself), shown on `thumbnail`.
KeyFrameView KeyFrameOf(const cv::Mat& thumbnail, std::vector<cv::Point2f> points, cv::Mat descriptors,
                        int feature_width);

// A loop closure between the prior patrol and the current one: its two map nodes and their key frames.
struct PlacePair {
  int prior_node = -1, current_node = -1;
  TimestampNs prior_ns = 0, current_ns = 0;
  KeyFrameView prior, current;
  std::optional<CameraPoseSample> current_pose;  // the current camera there, when the patrol has poses
};

// Why a check while flying holds its geometry and object changes back.
enum class HoldReason { kNone, kPosesDisagree, kUndecidedShift };

// What one check while flying found, in the prior's frame.
struct LiveFindings {
  HoldReason held = HoldReason::kNone;  // not kNone: no object is compared, and no region is to be sent
  bool geometry_compared = false;
  GeometryChange geometry;            // as compared (with the shift taken)
  std::vector<ObjectChange> objects;  // detected first, then class-agnostic
  GridShift search;                   // the alignment searched at this check (none searched: zero)
  bool shift_changed = false;         // this check took a new shift (shift())
};

class ChangeDetector {
 public:
  // Compares with `prior`, which outlives the detector.
  ChangeDetector(const PatrolRecord& prior, const ChangeOptions& options);

  const PatrolRecord& prior() const { return prior_; }

  // A finished patrol moved onto the prior when a whole-voxel shift is taken (its grid, objects, views and route
  // poses); the search.
  GridShift Align(PatrolRecord* current) const;

  // A finished patrol, already aligned, at the places both patrols closed loops at: the whole report (flights,
  // places, route, geometry, objects, where the poses came from, the time each channel took).
  void Compare(const PatrolRecord& current, const std::vector<PlacePair>& places, ChangeReport* report) const;

  // While flying: the key frames of a loop closure onto the prior.
  AppearanceChange ComparePlace(const KeyFrameView& prior, const KeyFrameView& current) const;
  // While flying: `now`, the record so far (objects, views), and its grid as it is being built (null without
  // depth), read in place. A
  // shift is searched while the poses disagree, or while none is taken and more of the surface differs than
  // right poses give (change.alignment.min_differing_share); a shift taken holds for later checks.
  LiveFindings Check(PatrolRecord now, const EvidenceGrid* grid);
  const Eigen::Vector3i& shift() const { return shift_; }

 private:
  // The objects of `current` against the prior's: detected ones when both patrols have detections, then, where
  // the grids were compared, the clusters of changed space `geometry` holds (`current_grid` is the current grid
  // in the prior's frame). Sets `compared` when either ran, and the detected ones' time (may be null).
  void FindObjects(const PatrolRecord& current, const GeometryChange& geometry, bool geometry_compared,
                   const VoxelLookup& current_grid, std::vector<ObjectChange>* objects, bool* compared,
                   double* seconds_detected) const;

  // A change seen in images, not placed by its frames' depth, placed on the current patrol's grid where its bearing
  // meets an occupied voxel (change_location.h).
  void OnGrid(const EvidenceGridData& grid, ChangeLocation* location) const;

  const PatrolRecord& prior_;
  ChangeOptions options_;
  // While flying: the shift taken so far and the prior grid's search, made at the first one.
  Eigen::Vector3i shift_ = Eigen::Vector3i::Zero();
  std::optional<ShiftSearch> shift_search_;
};

}  // namespace patrolmap::change
