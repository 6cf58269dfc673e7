#include "patrolmap/io/frame_source.h"

#include <spdlog/spdlog.h>

namespace patrolmap::io {

void FrameSource::RecordSkipped(std::int64_t index, std::string reason) {
  spdlog::warn("skipping frame {}: {}", index, reason);
  skipped_.push_back({index, std::move(reason)});
}

}  // namespace patrolmap::io
