// Camera poses from a file beside the log (`--poses FILE`), for logs without a state estimate: the change
// layer needs where the camera was. Two common formats, told apart by the number of values on a line:
//   TUM    8 values: timestamp [s], tx ty tz [m], qx qy qz qw   (the camera's pose in the world)
//   KITTI 12 values: the 3x4 matrix [R | t], row by row, world from camera, one line per image of the log
//                    in order (the file has no times: line i is the log's image i)
// Lines starting with '#' and blank lines are skipped. The world frame is the file's own (z need not be up).
#pragma once

#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

// Reads `path` into camera poses (world_from_camera, ascending time). `frame_times` are the times of the
// log's images (KITTI lines take them). Fails naming the file and line: a line of another length, a value
// that is not a finite number, a rotation that is not one, times out of order, a KITTI file with another
// number of lines than the log has images.
Status ReadPoseFile(const std::string& path, const std::vector<TimestampNs>& frame_times,
                    std::vector<CameraPoseSample>* poses);

}  // namespace patrolmap::io
