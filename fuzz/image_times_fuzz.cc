// Fuzzes the timestamps of an image folder: the input is split at NUL bytes into a times.txt and up to
// six image file names, whose times are read as FindImageTimes reads them.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_files.h"
#include "io/image_times.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder() / "images";
  const auto pieces = patrolmap::fuzz::SplitInput(data, size, 7);
  if (!pieces[0].empty()) patrolmap::fuzz::WriteBytes(folder / "times.txt", pieces[0]);
  std::vector<std::string> paths;
  for (std::size_t i = 1; i < pieces.size(); ++i) {
    if (pieces[i].empty() || pieces[i].find('/') != std::string_view::npos) continue;
    paths.push_back((folder / std::string(pieces[i])).string());
  }
  std::vector<patrolmap::TimestampNs> times;
  std::string source;
  if (patrolmap::io::FindImageTimes(folder.string(), paths, &times, &source).ok()) {
    (void)patrolmap::io::MedianRate(times);
  }
  return 0;
}
