#include "patrolmap/core/patrol_data.h"

#include <algorithm>
#include <cstdlib>

namespace patrolmap {

cv::Rect2d ProjectCorners(const CameraIntrinsics& camera, const CameraPoseSample& pose,
                          const std::array<Eigen::Vector3d, 8>& corners, const Distortion& distortion) {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const Eigen::Vector3d& corner : corners) {
    const Eigen::Vector3d c = pose.ToCamera(corner);
    if (c.z() < 0.1) return {};
    const Eigen::Vector2d seen = Distorted(distortion, c.head<2>() / c.z());
    const double u = camera.fx * seen.x() + camera.cx, v = camera.fy * seen.y() + camera.cy;
    x0 = std::min(x0, u), y0 = std::min(y0, v), x1 = std::max(x1, u), y1 = std::max(y1, v);
  }
  return cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
}

std::optional<CameraPoseSample> ViewAt(const PatrolRecord& record, TimestampNs timestamp_ns, TimestampNs tolerance_ns) {
  const auto nearest = std::min_element(
      record.views.begin(), record.views.end(), [timestamp_ns](const CameraPoseSample& a, const CameraPoseSample& b) {
        return std::llabs(a.timestamp_ns - timestamp_ns) < std::llabs(b.timestamp_ns - timestamp_ns);
      });
  if (nearest == record.views.end() || std::llabs(nearest->timestamp_ns - timestamp_ns) > tolerance_ns) {
    return std::nullopt;
  }
  return *nearest;
}

}  // namespace patrolmap
