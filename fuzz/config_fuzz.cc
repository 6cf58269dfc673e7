// Fuzzes the configuration loader (YAML over the defaults, then every option's check).
#include <cstddef>
#include <cstdint>

#include "fuzz_files.h"
#include "patrolmap/pipeline/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  patrolmap::fuzz::WriteBytes(folder / "config.yaml", {reinterpret_cast<const char*>(data), size});
  patrolmap::pipeline::Config config;
  (void)patrolmap::pipeline::LoadCheckedConfig((folder / "config.yaml").string(), &config);
  return 0;
}
