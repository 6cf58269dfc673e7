#include "patrolmap/core/types.h"

#include <cmath>

namespace patrolmap {

Eigen::Vector2d Distorted(const Distortion& d, const Eigen::Vector2d& point, bool* folded) {
  const auto& [k1, k2, p1, p2] = d;
  const double x = point.x(), y = point.y(), r2 = x * x + y * y;
  const bool beyond = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2 <= 0.0;
  if (folded != nullptr) *folded = beyond;
  if (beyond) return point;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

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
