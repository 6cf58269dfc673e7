// Fuzzes pose files (--poses): the input is the file; the log it belongs to has 4 images.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_files.h"
#include "patrolmap/io/pose_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  patrolmap::fuzz::WriteBytes(folder / "poses.txt", std::string_view(reinterpret_cast<const char*>(data), size));
  std::vector<patrolmap::CameraPoseSample> poses;
  if (patrolmap::io::ReadPoseFile((folder / "poses.txt").string(), {100, 200, 300, 400}, &poses).ok()) {
    for (const patrolmap::CameraPoseSample& pose : poses) {
      if (!pose.position.allFinite() || !(std::abs(pose.rotation.norm() - 1.0) < 1e-6)) __builtin_trap();
    }
  }
  return 0;
}
