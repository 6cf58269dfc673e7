#include "patrolmap/change/change_location.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include <opencv2/calib3d.hpp>

namespace patrolmap::change {

const char* ToString(LocatedBy by) {
  switch (by) {
    case LocatedBy::kDepth: return "depth";
    case LocatedBy::kGrid: return "grid";
    case LocatedBy::kTriangulated: return "triangulated";
    case LocatedBy::kBearing: return "bearing";
    case LocatedBy::kNone: break;
  }
  return "none";
}

Bearing BearingThrough(const CameraIntrinsics& camera, const Distortion& distortion, int image_width,
                       const CameraPoseSample& pose, const cv::Rect& box) {
  const double scale = static_cast<double>(image_width) / camera.width;
  const Eigen::Vector2d centre((box.x + box.width / 2.0) / scale, (box.y + box.height / 2.0) / scale);
  Eigen::Vector3d ray((centre.x() - camera.cx) / camera.fx, (centre.y() - camera.cy) / camera.fy, 1.0);
  if (std::any_of(distortion.begin(), distortion.end(), [](double k) { return k != 0.0; })) {
    const cv::Matx33d k(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
    std::vector<cv::Point2d> raw{cv::Point2d(centre.x(), centre.y())}, normalised;
    cv::undistortPoints(raw, normalised, k, cv::Mat(std::vector<double>(distortion.begin(), distortion.end())));
    if (std::isfinite(normalised[0].x) && std::isfinite(normalised[0].y)) {
      ray = Eigen::Vector3d(normalised[0].x, normalised[0].y, 1.0);
    }
  }
  return {pose.position, (pose.rotation * ray).normalized()};
}

ChangeLocation BearingOfLargest(const AppearanceChange& change, const CameraIntrinsics& camera,
                                const Distortion& distortion, int image_width,
                                const std::optional<CameraPoseSample>& pose) {
  ChangeLocation location;
  const auto largest =
      std::max_element(change.regions.begin(), change.regions.end(),
                       [](const AppearanceRegion& a, const AppearanceRegion& b) { return a.area_px < b.area_px; });
  if (largest == change.regions.end() || !pose || !camera.valid() || image_width <= 0) return location;
  location.by = LocatedBy::kBearing;
  location.bearing = BearingThrough(camera, distortion, image_width, *pose, largest->current_box);
  return location;
}

std::optional<Eigen::Vector3d> PointFromDepth(const KeyFrameView& view, const cv::Rect& box,
                                              const ChangeLocationOptions& options) {
  if (view.depth.empty() || view.lens.camera().width != view.depth.cols) return std::nullopt;
  const cv::Rect inside = box & cv::Rect(0, 0, view.depth.cols, view.depth.rows);
  if (inside.area() <= 0) return std::nullopt;
  std::vector<float> known;
  known.reserve(inside.area());
  for (int v = inside.y; v < inside.br().y; ++v) {
    const float* row = view.depth.ptr<float>(v);
    for (int u = inside.x; u < inside.br().x; ++u) {
      if (row[u] > 0.0f && std::isfinite(row[u])) known.push_back(row[u]);
    }
  }
  if (known.empty() || known.size() < options.min_depth_share * inside.area()) return std::nullopt;
  std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
  const double z = known[known.size() / 2];
  if (z > options.max_range_m) return std::nullopt;
  const Eigen::Vector3d in_camera = z * view.lens.Ray(inside.x + inside.width / 2, inside.y + inside.height / 2);
  return view.pose.rotation * in_camera + view.pose.position;
}

std::optional<Eigen::Vector3d> FirstSurface(const VoxelLookup& grid, double voxel_size, const Bearing& bearing,
                                            const ChangeLocationOptions& options) {
  if (!grid || voxel_size <= 0.0) return std::nullopt;
  const double step = voxel_size / 2.0;
  const int steps = static_cast<int>(options.max_range_m / step);
  Eigen::Vector3i last(INT32_MIN, INT32_MIN, INT32_MIN);
  for (int i = 1; i <= steps; ++i) {
    const Eigen::Vector3i index = VoxelIndex(bearing.origin + i * step * bearing.direction, voxel_size);
    if (index == last) continue;
    last = index;
    VoxelEvidence voxel;
    if (grid(index, &voxel) && IsOccupied(&voxel)) return index.cast<double>() * voxel_size;
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> Triangulate(const std::vector<Bearing>& rays, const ChangeLocationOptions& options) {
  if (rays.size() < 2) return std::nullopt;
  double smallest_cos = 1.0;  // of the widest angle between two rays
  for (std::size_t i = 0; i < rays.size(); ++i) {
    for (std::size_t j = i + 1; j < rays.size(); ++j) {
      smallest_cos = std::min(smallest_cos, rays[i].direction.dot(rays[j].direction));
    }
  }
  const double widest = std::acos(std::clamp(smallest_cos, -1.0, 1.0)) * 180.0 / M_PI;
  if (widest < options.min_ray_angle_deg) return std::nullopt;
  // The point nearest all lines: sum over rays of (I - d d^T) p = sum of (I - d d^T) o.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Bearing& ray : rays) {
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - ray.direction * ray.direction.transpose();
    a += across;
    b += across * ray.origin;
  }
  const Eigen::Vector3d point = a.ldlt().solve(b);
  if (!point.allFinite()) return std::nullopt;
  for (const Bearing& ray : rays) {
    const double along = (point - ray.origin).dot(ray.direction);
    if (along <= 0.0 || along > options.max_range_m) return std::nullopt;
  }
  return point;
}

}  // namespace patrolmap::change
