// A digest of a flight log's content, to tell a log already in a map from another log that shares its name.
#pragma once

#include <string>

namespace patrolmap::io {

// 16 hex digits over what the log at `path` holds: a file's size and its first and last MiB; a folder's files
// (their paths inside it, sizes, and the first and last MiB of its largest file), found without following links.
// A copy of a log has the digest of the original; two flights differ. "" when `path` cannot be read (a camera).
std::string LogDigest(const std::string& path);

}  // namespace patrolmap::io
