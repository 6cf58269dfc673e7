// File helpers shared by every stage that writes results.
#pragma once

#include <cstddef>
#include <string>

#include "patrolmap/core/status.h"

namespace patrolmap {

// A file written atomically in pieces: a temporary file beside `path` (path.tmp.<pid>) takes the pieces and
// Commit() flushes it to disk and renames it over `path`, so readers see either the old file or the complete
// new one, never a half-written file. Without a successful Commit() the temporary is removed. Temporaries of
// `path` left by a process that no longer runs (a killed run) are removed when it opens.
class AtomicFile {
 public:
  static Status Open(const std::string& path, AtomicFile* file);
  AtomicFile() = default;
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  Status Write(const char* data, std::size_t size);
  Status Write(const std::string& bytes) { return Write(bytes.data(), bytes.size()); }
  Status Commit();
  // The temporary, for a writer that fills it by its own means (an SQLite database); Commit() then flushes and
  // renames it as it would the pieces.
  const std::string& temporary_path() const { return temporary_; }

 private:
  void Abandon();

  std::string path_, temporary_;
  int fd_ = -1;
  int slot_ = -1;  // in the table RemoveTemporariesOnSignal's handler reads
};

// Makes SIGINT, SIGTERM and SIGHUP remove the AtomicFile temporaries being written before the process ends as the
// signal would end it (a temporary left by SIGKILL is removed by the next writer of that file).
void RemoveTemporariesOnSignal();

// Writes `content` to `path` atomically (AtomicFile).
Status WriteFileAtomically(const std::string& path, const std::string& content);

// Whether `path` names something (a file, a folder, a link that leads somewhere). Never throws: a name too long, a
// loop of links or a folder that cannot be searched count as nothing there.
bool PathExists(const std::string& path);

// Creates `path` and its parents when missing.
Status EnsureDirectory(const std::string& path);

// True when `a` and `b` name the same file (or folder), also through links or "..": an output that is an
// input must be refused before anything is written.
bool SameFile(const std::string& a, const std::string& b);

// Fails "OUTPUT would replace INPUT (the WHAT); choose another output" when they are the same file, or when INPUT
// is a folder (a flight log) that holds OUTPUT as one of its files.
Status RefuseOverwritingInput(const std::string& output, const std::string& input, const std::string& what);

// The files an output folder of `map`, `patrol` and `patrolmap-onboard` may receive.
extern const char* const kMapOutputFiles[11];

// RefuseOverwritingInput for each of kMapOutputFiles in `folder` and an input file (a pose file, a configuration).
Status RefuseOverwritingInFolder(const std::string& folder, const std::string& input, const std::string& what);

}  // namespace patrolmap
