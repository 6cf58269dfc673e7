#include "patrolmap/core/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace patrolmap {
namespace {

Status WriteAll(int fd, const std::string& content, const std::string& path) {
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return Status::IoError(path + ": write failed: " + std::strerror(errno));
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return Status::Ok();
}

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

}  // namespace

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  if (std::filesystem::equivalent(a, b, error) && !error) return true;
  const auto canonical_a = std::filesystem::weakly_canonical(a, error);
  if (error) return false;
  const auto canonical_b = std::filesystem::weakly_canonical(b, error);
  return !error && canonical_a == canonical_b;
}

Status RefuseOverwritingInput(const std::string& output, const std::string& input, const std::string& what) {
  if (!SameFile(output, input)) return Status::Ok();
  return Status::InvalidArgument(output + " would replace " + input + " (the " + what + "); choose another output");
}

Status WriteFileAtomically(const std::string& path, const std::string& content) {
  RemoveStaleTemporaries(path);
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Status::IoError(temporary + ": cannot create: " + std::strerror(errno));
  Status status = WriteAll(fd, content, temporary);
  if (status.ok() && ::fsync(fd) != 0) {
    status = Status::IoError(temporary + ": fsync failed: " + std::strerror(errno));
  }
  if (::close(fd) != 0 && status.ok()) {
    status = Status::IoError(temporary + ": close failed: " + std::strerror(errno));
  }
  if (status.ok() && std::rename(temporary.c_str(), path.c_str()) != 0) {
    status = Status::IoError(path + ": rename failed: " + std::strerror(errno));
  }
  if (!status.ok()) std::remove(temporary.c_str());
  return status;
}

Status EnsureDirectory(const std::string& path) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error) return Status::IoError(path + ": cannot create folder: " + error.message());
  if (!std::filesystem::is_directory(path)) return Status::IoError(path + ": is not a folder");
  return Status::Ok();
}

}  // namespace patrolmap
