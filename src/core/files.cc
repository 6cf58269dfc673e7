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

}  // namespace

Status WriteFileAtomically(const std::string& path, const std::string& content) {
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
