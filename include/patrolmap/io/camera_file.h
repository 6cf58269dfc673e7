// A camera's calibration from a file (`--camera FILE`), for logs that carry none: image folders and patterns. The
// layout is EuRoC's cam0/sensor.yaml: `intrinsics: [fx, fy, cx, cy]`, `resolution: [width, height]`, and, for a lens
// that distorts, `distortion_model: radial-tangential` with `distortion_coefficients: [k1, k2, p1, p2]`.
#pragma once

#include <string>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

// Fails naming the file and the key when it cannot be read, a value is missing or not a finite number, the
// intrinsics are not positive, or the distortion model is another than radial-tangential.
Status ReadCameraFile(const std::string& path, CameraIntrinsics* camera, Distortion* distortion);

}  // namespace patrolmap::io
