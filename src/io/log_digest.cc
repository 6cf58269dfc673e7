#include "patrolmap/io/log_digest.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "patrolmap/core/checksum.h"

namespace patrolmap::io {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kEndBytes = 1 << 20;          // read from each end of a file
constexpr std::size_t kMaxFolderEntries = 2000000;  // a folder larger than any log is digested by its first ones

std::uint64_t FoldValue(std::uint64_t value, std::uint64_t hash) {
  return Checksum(reinterpret_cast<const char*>(&value), sizeof(value), hash);
}

// The file's size, first and last kEndBytes into `hash`.
std::uint64_t FoldFile(const fs::path& file, std::uintmax_t size, std::uint64_t hash) {
  hash = FoldValue(size, hash);
  std::ifstream stream(file, std::ios::binary);
  std::vector<char> buffer(static_cast<std::size_t>(std::min<std::uintmax_t>(size, kEndBytes)));
  for (const std::uintmax_t start : {std::uintmax_t{0}, size - buffer.size()}) {
    stream.seekg(static_cast<std::streamoff>(start));
    stream.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    hash = Checksum(buffer.data(), static_cast<std::size_t>(stream.gcount()), hash);
  }
  return hash;
}

std::uint64_t FoldFolder(const fs::path& folder, std::uint64_t hash) {
  std::vector<std::pair<std::string, std::uintmax_t>> files;
  std::error_code error;
  fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, error), end;
  for (; !error && it != end && files.size() < kMaxFolderEntries; it.increment(error)) {
    std::error_code ignored;
    if (!it->is_regular_file(ignored)) continue;  // links are not followed: a loop ends nowhere
    const std::uintmax_t size = it->file_size(ignored);
    files.emplace_back(it->path().lexically_relative(folder).generic_string(), ignored ? 0 : size);
  }
  std::sort(files.begin(), files.end());
  const std::pair<std::string, std::uintmax_t>* largest = nullptr;
  for (const auto& file : files) {
    hash = Checksum(file.first.data(), file.first.size() + 1, hash);  // with its terminating zero
    hash = FoldValue(file.second, hash);
    if (largest == nullptr || file.second > largest->second) largest = &file;
  }
  if (largest != nullptr) hash = FoldFile(folder / largest->first, largest->second, hash);
  return hash;
}

}  // namespace

std::string LogDigest(const std::string& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  std::uint64_t hash = kChecksumSeed;
  if (fs::is_directory(status)) {
    // A EuRoC log given as LOG or as LOG/mav0 is one log.
    const bool euroc_root = !fs::exists(fs::path(path) / "cam0", error) && fs::exists(fs::path(path) / "mav0", error);
    hash = FoldFolder(euroc_root ? fs::path(path) / "mav0" : fs::path(path), hash);
  } else if (fs::is_regular_file(status)) {
    const std::uintmax_t size = fs::file_size(path, error);
    if (error) return "";
    hash = FoldFile(path, size, hash);
  } else {
    return "";
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace patrolmap::io
