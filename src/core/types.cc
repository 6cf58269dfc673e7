#include "patrolmap/core/types.h"

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

}  // namespace patrolmap
