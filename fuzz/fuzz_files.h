// Fuzzing helpers: the parsers under test read files, so a harness writes its input to a scratch folder
// of its own process and hands the parser the path (the same entry point a user's file reaches).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/spdlog.h>
#include <opencv2/core/utils/logger.hpp>

namespace patrolmap::fuzz {

// Millions of inputs: the warnings a user needs would only slow the fuzzer down.
inline void Quiet() {
  static const bool quiet = [] {
    spdlog::set_level(spdlog::level::off);
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;
}

// The scratch folder of this process, removed when the process ends (the corpus replay of scripts/test.sh
// would otherwise leave one per harness in $TMPDIR).
class ScratchFolder {
 public:
  ScratchFolder() : path_(std::filesystem::temp_directory_path() / ("patrolmap_fuzz_" + std::to_string(getpid()))) {}
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A folder that exists for this process: $TMPDIR/patrolmap_fuzz_<pid>, emptied on each call. Logging is
// off from the first call on.
inline std::filesystem::path FreshFolder() {
  Quiet();
  static const ScratchFolder folder;
  std::error_code ignored;
  std::filesystem::remove_all(folder.path(), ignored);
  std::filesystem::create_directories(folder.path());
  return folder.path();
}

inline void WriteBytes(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Splits an input into at most `parts` pieces at NUL bytes (several files from one input); missing pieces
// are empty.
inline std::vector<std::string_view> SplitInput(const std::uint8_t* data, std::size_t size, std::size_t parts) {
  std::vector<std::string_view> pieces;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  while (pieces.size() + 1 < parts) {
    const std::size_t end = rest.find('\0');
    if (end == std::string_view::npos) break;
    pieces.push_back(rest.substr(0, end));
    rest.remove_prefix(end + 1);
  }
  pieces.push_back(rest);
  pieces.resize(parts);
  return pieces;
}

}  // namespace patrolmap::fuzz
