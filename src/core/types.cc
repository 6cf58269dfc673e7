#include "patrolmap/core/types.h"

#include <cmath>

namespace patrolmap {

CameraIntrinsics CameraIntrinsics::Scaled(double scale) const {
  CameraIntrinsics scaled = *this;
  scaled.fx *= scale;
  scaled.fy *= scale;
  // Pixel centres: x_scaled + 0.5 = (x + 0.5) * scale.
  scaled.cx = (cx + 0.5) * scale - 0.5;
  scaled.cy = (cy + 0.5) * scale - 0.5;
  scaled.width = static_cast<int>(width * scale + 0.5);
  scaled.height = static_cast<int>(height * scale + 0.5);
  return scaled;
}

const char* ToString(ExtremumKind kind) { return kind == ExtremumKind::kPeak ? "peak" : "valley"; }

std::array<Eigen::Vector3d, 8> StandingBoxCorners(const Eigen::Vector2d& centre, double yaw, double length,
                                                  double width, double height) {
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), across(-along.y(), along.x());
  std::array<Eigen::Vector3d, 8> corners;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector2d ground =
        centre + ((k & 1) ? 0.5 : -0.5) * length * along + ((k & 2) ? 0.5 : -0.5) * width * across;
    corners[k] = Eigen::Vector3d(ground.x(), ground.y(), (k & 4) ? height : 0.0);
  }
  return corners;
}

}  // namespace patrolmap
