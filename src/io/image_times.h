// Internal: timestamps of an image folder's frames, when the folder carries them.
#pragma once

#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

// Looks for the times of `paths` (the folder's images in natural order), in order:
//  - a times file `times.txt` in the folder or its parent (KITTI): one time in seconds per line, as many
//    lines as images;
//  - the file names, when every name's stem is a number: seconds with a fraction (TUM:
//    1305031102.175304.png), or an integer of at least 10 digits read as seconds, milliseconds,
//    microseconds or nanoseconds by its size (EuRoC: 1403636579763555584.png).
// Times must increase. Fills `times` and names the source in `source` ("times.txt", "file names"), or
// leaves both empty when the folder has no times. A times file that does not fit fails naming it and
// the line.
Status FindImageTimes(const std::string& folder, const std::vector<std::string>& paths, std::vector<TimestampNs>* times,
                      std::string* source);

// The rate of increasing `times`: one over their median interval [Hz]; 0 for fewer than two.
double MedianRate(const std::vector<TimestampNs>& times);

}  // namespace patrolmap::io
