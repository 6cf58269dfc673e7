// File helpers shared by every stage that writes results.
#pragma once

#include <string>

#include "patrolmap/core/status.h"

namespace patrolmap {

// Writes `content` to `path` atomically: a temporary file beside it is written,
// flushed to disk and renamed over `path`, so readers see either the old file
// or the complete new one, never a half-written file.
Status WriteFileAtomically(const std::string& path, const std::string& content);

// Writes `content` to `path` atomically: ... (above). Temporaries of `path` left by a process that no longer
// runs (path.tmp.<pid>, a killed run) are removed first.

// Creates `path` and its parents when missing.
Status EnsureDirectory(const std::string& path);

// True when `a` and `b` name the same file (or folder), also through links or "..": an output that is an
// input must be refused before anything is written.
bool SameFile(const std::string& a, const std::string& b);

// Fails "OUTPUT would replace INPUT (the WHAT); choose another output" when they are the same file.
Status RefuseOverwritingInput(const std::string& output, const std::string& input, const std::string& what);

}  // namespace patrolmap
