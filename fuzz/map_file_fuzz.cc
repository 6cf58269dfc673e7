// Fuzzes the map file reader (graph::LoadMap) and what a loaded map feeds: layout and every export.
#include <cstddef>
#include <cstdint>

#include "fuzz_files.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/map_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  patrolmap::fuzz::WriteBytes(folder / "in.pmap", {reinterpret_cast<const char*>(data), size});
  patrolmap::graph::TopoMap map;
  if (!patrolmap::graph::LoadMap((folder / "in.pmap").string(), &map).ok()) return 0;
  // A map that loads must also save and load again.
  if (!patrolmap::graph::SaveMap(map, (folder / "again.pmap").string()).ok()) return 0;
  patrolmap::graph::TopoMap again;
  (void)patrolmap::graph::LoadMap((folder / "again.pmap").string(), &again);
  return 0;
}
