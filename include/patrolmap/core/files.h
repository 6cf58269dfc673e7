// File helpers shared by every stage that writes results.
#pragma once

#include <string>

#include "patrolmap/core/status.h"

namespace patrolmap {

// Writes `content` to `path` atomically: a temporary file beside it is written,
// flushed to disk and renamed over `path`, so readers see either the old file
// or the complete new one, never a half-written file.
Status WriteFileAtomically(const std::string& path, const std::string& content);

// Creates `path` and its parents when missing.
Status EnsureDirectory(const std::string& path);

}  // namespace patrolmap
