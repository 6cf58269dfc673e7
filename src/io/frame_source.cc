#include "patrolmap/io/frame_source.h"

#include <spdlog/spdlog.h>

#include "patrolmap/core/flight_id.h"

namespace patrolmap::io {

std::string CleanFlightId(const std::string& raw) {
  const std::string id = CleanedFlightId(raw);
  if (id != raw && !raw.empty())
    spdlog::warn("flight id '{}' contains characters a table, a file name or UTF-8 cannot hold; it is '{}' here", raw, id);
  return id;
}

Status FrameSource::UsePoseFile(const std::string& path) {
  return Status::InvalidArgument(path +
                                 ": poses from a file need a log whose frame times are known before it is "
                                 "read (an image folder or a EuRoC log), not a " +
                                 info().kind);
}

Status FrameSource::UseCameraFile(const std::string& path) {
  return Status::InvalidArgument(path + ": a camera file calibrates an image folder, pattern or EuRoC log, not a " +
                                 info().kind);
}

void FrameSource::RecordSkipped(std::int64_t index, std::string reason) {
  spdlog::warn("skipping frame {}: {}", index, reason);
  skipped_.push_back({index, std::move(reason)});
}

}  // namespace patrolmap::io
