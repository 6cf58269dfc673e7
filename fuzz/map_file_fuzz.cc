// Fuzzes the map file reader (graph::LoadMap) and what a loaded map feeds: a save and every export. A format-12
// input whose first byte is odd gets its section checksums recomputed first, so mutations reach the parsers behind
// them; even ones test the checksums themselves. SQLite maps (format 13) are read as they come.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_files.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/map_file.h"
#include "recompute_checksums.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  std::string bytes(reinterpret_cast<const char*>(data), size);
  // An SQLite map (format 13) is given to the reader as it is; SQLite checks its own pages.
  const bool database = size >= 16 && std::memcmp(data, "SQLite format 3", 16) == 0;
  if (!database && size > 0 && (data[0] & 1) != 0) {
    bytes[0] = 'P';  // the magic's first byte, so the recomputed file can load
    patrolmap::testing::RecomputeMapChecksums(&bytes);
  }
  patrolmap::fuzz::WriteBytes(folder / "in.pmap", bytes);
  patrolmap::graph::TopoMap map;
  if (!patrolmap::graph::LoadMap((folder / "in.pmap").string(), &map).ok()) return 0;
  for (const std::string& text :
       {patrolmap::graph::ToGraphML(map), patrolmap::graph::ToDot(map), patrolmap::graph::ToJson(map),
        patrolmap::graph::ToSvg(map), patrolmap::graph::ToHtml(map), patrolmap::graph::ToGeoJson(map),
        patrolmap::graph::ToKml(map)}) {
    (void)text;
  }
  // A map that loads must also save and load again.
  if (!patrolmap::graph::SaveMap(map, (folder / "again.pmap").string()).ok()) return 0;
  patrolmap::graph::TopoMap again;
  (void)patrolmap::graph::LoadMap((folder / "again.pmap").string(), &again);
  return 0;
}
