// The state of every object between two patrols (papers 000, 001, 003):
//   persistent  a current object of the same label within the match distance
//               of a prior one (and passing the point-pair test when both have points);
//   moved       a prior object gone from its place paired with a new object of the
//               same label, alike in texture, shape and top height, by paper 003's
//               weighted, min-max normalised physical and appearance distance; the
//               rigid motion by SVD of the point covariances;
//   removed     a prior object nothing matched although the current views covering
//               it (in range, half its box inside the image, not behind occupied voxels
//               of the current evidence grid other than those of a current object that
//               may be it, moved) would have detected it often enough: at least
//               min_expected_detections times, its prior detections scaled by the
//               ratio of the covering views now and in its own patrol;
//   unobserved  a prior object the current patrol did not see well enough to tell;
//   new         a current object matching nothing of the prior patrol.
// Unconfirmed objects (seen too few times) take part only in the persistent
// matching: a current object at the place of an unconfirmed prior one is
// persistent, not new; unconfirmed objects are never reported themselves.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

enum class ObjectState { kPersistent, kNew, kRemoved, kMoved, kUnobserved };
const char* ToString(ObjectState state);
bool ParseObjectState(const std::string& text, ObjectState* state);

struct ObjectChange {
  ObjectState state = ObjectState::kPersistent;
  std::string label;
  double confidence = 0.0;                // in [0, 1]
  int prior_id = -1, current_id = -1;     // object ids in the two patrols' object maps
  std::optional<Eigen::Vector3d> before;  // prior position (not for new)
  std::optional<Eigen::Vector3d> after;   // current position (not for removed or unobserved)
  int covering_views = 0;                 // current views that covered the prior object
  double expected_detections = 0.0;       // detections they would have given of it (removed, unobserved, moved)
  // moved: after ~ rotation * (before-point - before) + after, from the SVD registration.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double weighted_distance = 0.0;  // moved: paper 003's delta
  // From changed geometry (GeometryObjects), not from a detector: no object ids, label "object", and the
  // extent of the changed voxels where it was and where it is (empty boxes where it is not).
  bool class_agnostic = false;
  Eigen::AlignedBox3d box_before, box_after;
  int site_id = -1;  // the site object it concerns (change/site_objects.h); -1 for none
};

// The appearance terms between two objects, each in [0, 1] and present when both have it: texture (half
// the L1 distance of the gradient-orientation histograms), brightness (difference of the brightness
// ranks) and height (difference relative to the taller).
struct AppearanceTerms {
  std::optional<double> texture, brightness, height;
  double Distance() const;  // mean of the present terms; 0 when none
};
AppearanceTerms CompareAppearance(const MapObject& a, const MapObject& b);

// Share of the object's projected box inside the image; 0 when a corner lies behind the camera.
double VisibleFraction(const MapObject& object, const CameraIntrinsics& camera, const CameraPoseSample& view);

// How many of the patrol's views cover `object`: its centroid in front and
// within range, at least min_visible_fraction of its box inside the image, and
// (with a grid) no occupied voxel on the line of sight short of the object's
// half size (at least 1 m) before it. Voxels inside `see_through` (current
// objects that may be this one, moved) do not hide it.
int CoveringViews(const MapObject& object, const PatrolRecord& patrol, const ObjectDiffOptions& options,
                  const std::vector<const MapObject*>& see_through = {});

// Detections `views` covering views would give of `object`: its detections scaled by how many views covered
// it then (`own_views`, in its own patrol) and now; one per view when no own view covered it.
double ExpectedDetections(const MapObject& object, int own_views, int views);

std::vector<ObjectChange> DiffObjects(const PatrolRecord& prior, const PatrolRecord& current,
                                      const ObjectDiffOptions& options);

// Rotation taking `before` onto `after` (paper 003): centroids aligned, the
// principal axes of the two covariances matched by SVD, each axis signed by
// the skew of the points along it. Identity when either has fewer than 10 points.
Eigen::Matrix3d RegisterRotation(const std::vector<Eigen::Vector3f>& before, const std::vector<Eigen::Vector3f>& after);

}  // namespace patrolmap::change
