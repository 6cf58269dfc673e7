#include "patrolmap/core/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace patrolmap {
namespace {

// Removes path.tmp.<pid> files whose process is gone.
void RemoveStaleTemporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const std::string prefix = target.filename().string() + ".tmp.";
  std::error_code error;
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid.size() > 9) continue;
    if (std::stol(pid) == ::getpid() || fs::exists("/proc/" + pid)) continue;
    std::error_code ignored;
    fs::remove(it->path(), ignored);
  }
}

// The temporaries being written, for a signal handler to remove: a fixed table, so that the handler neither
// allocates nor locks. A slot's path is written before the slot is marked used.
constexpr int kTemporarySlots = 16;
constexpr std::size_t kTemporaryPathBytes = 4096;
std::atomic<bool> slot_claimed[kTemporarySlots];  // taken by a writer
std::atomic<bool> slot_used[kTemporarySlots];     // its path written: the handler may read it
char slot_path[kTemporarySlots][kTemporaryPathBytes];

int RegisterTemporary(const std::string& path) {
  if (path.size() >= kTemporaryPathBytes) return -1;
  for (int slot = 0; slot < kTemporarySlots; ++slot) {
    bool expected = false;
    if (!slot_claimed[slot].compare_exchange_strong(expected, true)) continue;  // another file's, or thread's
    std::memcpy(slot_path[slot], path.c_str(), path.size() + 1);
    slot_used[slot].store(true);
    return slot;
  }
  return -1;  // more files open at once than slots: such a file is left to the next writer's clean-up
}

void UnregisterTemporary(int slot) {
  if (slot < 0) return;
  slot_used[slot].store(false);
  slot_claimed[slot].store(false);
}

extern "C" void RemoveTemporariesAndDie(int signal_number) {
  for (int slot = 0; slot < kTemporarySlots; ++slot) {
    if (slot_used[slot].load()) ::unlink(slot_path[slot]);
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

}  // namespace

void RemoveTemporariesOnSignal() {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal_number, RemoveTemporariesAndDie);
}

bool PathExists(const std::string& path) {
  std::error_code error;
  return std::filesystem::exists(path, error);
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  if (std::filesystem::equivalent(a, b, error) && !error) return true;
  const auto canonical_a = std::filesystem::weakly_canonical(a, error);
  if (error) return false;
  const auto canonical_b = std::filesystem::weakly_canonical(b, error);
  return !error && canonical_a == canonical_b;
}

// Whether `path` names an existing file inside the folder `folder` (at any depth, through links and "..").
bool FileInside(const std::string& path, const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_regular_file(path, error) || !fs::is_directory(folder, error)) return false;
  const fs::path file = fs::weakly_canonical(path, error), root = fs::weakly_canonical(folder, error);
  if (error) return false;
  const fs::path relative = file.lexically_relative(root);
  return !relative.empty() && *relative.begin() != "..";
}

Status RefuseOverwritingInput(const std::string& output, const std::string& input, const std::string& what) {
  if (!SameFile(output, input) && !FileInside(output, input)) return Status::Ok();
  return Status::InvalidArgument(output + " would replace " + input + " (the " + what + "); choose another output");
}

const char* const kMapOutputFiles[11] = {"map.pmap",        "nodes.csv",    "loop_closures.csv", "key_locations.csv",
                                         "response.csv",    "response.svg", "changes.json",      "changes.html",
                                         "changes.geojson", "changes.kml",  "events.jsonl"};

Status RefuseOverwritingInFolder(const std::string& folder, const std::string& input, const std::string& what) {
  if (input.empty()) return Status::Ok();
  for (const char* name : kMapOutputFiles) {
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInput(folder + "/" + name, input, what));
  }
  return Status::Ok();
}

Status AtomicFile::Open(const std::string& path, AtomicFile* file) {
  file->Abandon();
  RemoveStaleTemporaries(path);
  file->path_ = path;
  file->temporary_ = path + ".tmp." + std::to_string(::getpid());
  file->slot_ = RegisterTemporary(file->temporary_);
  file->fd_ = ::open(file->temporary_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (file->fd_ < 0) {
    UnregisterTemporary(file->slot_);
    file->slot_ = -1;
    return Status::IoError(file->temporary_ + ": cannot create: " + std::strerror(errno));
  }
  return Status::Ok();
}

AtomicFile::~AtomicFile() { Abandon(); }

void AtomicFile::Abandon() {
  if (fd_ < 0) return;
  ::close(fd_);
  std::remove(temporary_.c_str());
  UnregisterTemporary(slot_);
  fd_ = -1, slot_ = -1;
}

Status AtomicFile::Write(const char* data, std::size_t size) {
  if (fd_ < 0) return Status::IoError(path_ + ": write to a file that is not open");
  while (size > 0) {
    const ssize_t written = ::write(fd_, data, size);
    if (written < 0) {
      if (errno == EINTR) continue;
      const Status status = Status::IoError(temporary_ + ": write failed: " + std::strerror(errno));
      Abandon();
      return status;
    }
    data += written;
    size -= static_cast<std::size_t>(written);
  }
  return Status::Ok();
}

Status AtomicFile::Commit() {
  if (fd_ < 0) return Status::IoError(path_ + ": commit of a file that is not open");
  Status status;
  if (::fsync(fd_) != 0) status = Status::IoError(temporary_ + ": fsync failed: " + std::strerror(errno));
  if (::close(fd_) != 0 && status.ok())
    status = Status::IoError(temporary_ + ": close failed: " + std::strerror(errno));
  fd_ = -1;
  if (status.ok() && std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    status = Status::IoError(path_ + ": rename failed: " + std::strerror(errno));
  }
  if (!status.ok()) std::remove(temporary_.c_str());
  UnregisterTemporary(slot_);
  slot_ = -1;
  return status;
}

Status WriteFileAtomically(const std::string& path, const std::string& content) {
  AtomicFile file;
  PATROLMAP_RETURN_IF_ERROR(AtomicFile::Open(path, &file));
  PATROLMAP_RETURN_IF_ERROR(file.Write(content));
  return file.Commit();
}

Status EnsureDirectory(const std::string& path) {
  if (path.empty()) return Status::InvalidArgument("the output folder is empty (--out \"\"?): name one");
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error) return Status::IoError(path + ": cannot create folder: " + error.message());
  if (!std::filesystem::is_directory(path, error)) return Status::IoError(path + ": is not a folder");
  return Status::Ok();
}

}  // namespace patrolmap
