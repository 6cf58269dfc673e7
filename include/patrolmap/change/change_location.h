// Where a change seen in images stands in the world. A region of a frame is a bearing from the camera; its
// distance comes, best first, from
//   depth         the frame's own depth (motion stereo along the route, route_depth.h): the median over the region
//   grid          the current patrol's evidence grid (depth images or stereo): the first occupied voxel on the ray
//   triangulated  the rays of the views that saw it, from poses far enough apart (their widest angle at least
//                 min_ray_angle_deg): the point nearest all of them
// and otherwise it stays a bearing: the ray from the camera, never a point at the camera.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/types.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/options.h"
#include "patrolmap/core/types.h"

namespace patrolmap::change {

enum class LocatedBy { kNone, kDepth, kGrid, kTriangulated, kBearing };
const char* ToString(LocatedBy by);  // "none", "depth", "grid", "triangulated", "bearing"

// A ray from a camera centre, in the world frame (unit direction).
struct Bearing {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

struct ChangeLocation {
  LocatedBy by = LocatedBy::kNone;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // world [m]: depth, grid, triangulated
  Bearing bearing;                                  // the best view's ray: every kind but kNone
  bool HasPoint() const { return by == LocatedBy::kDepth || by == LocatedBy::kGrid || by == LocatedBy::kTriangulated; }
};

// The ray through the centre of `box` (pixels of an image `image_width` wide) of a camera `camera` (intrinsics at
// its own size) standing at `pose`.
Bearing BearingThrough(const CameraIntrinsics& camera, const Distortion& distortion, int image_width,
                       const CameraPoseSample& pose, const cv::Rect& box);

// The bearing of a key frame's appearance change: the ray through its largest region (in an image `image_width`
// wide); kNone without a region, a pose or a valid camera.
ChangeLocation BearingOfLargest(const AppearanceChange& change, const CameraIntrinsics& camera,
                                const Distortion& distortion, int image_width,
                                const std::optional<CameraPoseSample>& pose);

// The point the depth of `view` (KeyFrameView::depth, lens and pose) puts at the centre of `box`: the median depth
// of the box's pixels, when at least min_depth_share of them know theirs.
std::optional<Eigen::Vector3d> PointFromDepth(const KeyFrameView& view, const cv::Rect& box,
                                              const ChangeLocationOptions& options);

// The first occupied voxel's centre along `bearing` in `grid` (voxels of `voxel_size`), within max_range_m.
std::optional<Eigen::Vector3d> FirstSurface(const VoxelLookup& grid, double voxel_size, const Bearing& bearing,
                                            const ChangeLocationOptions& options);

// The point nearest all `rays` (least squares), when their widest angle is at least min_ray_angle_deg and the point
// stands in front of every camera within max_range_m.
std::optional<Eigen::Vector3d> Triangulate(const std::vector<Bearing>& rays, const ChangeLocationOptions& options);

}  // namespace patrolmap::change
