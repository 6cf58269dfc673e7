#include "patrolmap/io/frame_source.h"

#include <spdlog/spdlog.h>

namespace patrolmap::io {

std::string CleanFlightId(const std::string& raw) {
  std::string id;
  for (unsigned char c : raw) id += (c < 0x20 || c == 0x7f || c == ',' || c == '"') ? '_' : static_cast<char>(c);
  if (id.size() > kMaxFlightIdLength) id.resize(kMaxFlightIdLength);
  if (id.empty()) id = "flight";
  if (id != raw) spdlog::warn("flight id '{}' contains characters tables cannot hold; it is '{}' here", raw, id);
  return id;
}

void FrameSource::RecordSkipped(std::int64_t index, std::string reason) {
  spdlog::warn("skipping frame {}: {}", index, reason);
  skipped_.push_back({index, std::move(reason)});
}

}  // namespace patrolmap::io
