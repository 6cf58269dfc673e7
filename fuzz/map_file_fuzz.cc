// Fuzzes the map file reader (graph::LoadMap) and what a loaded map feeds: a save and every export. An
// input whose first byte is odd gets its section checksums recomputed first, so mutations reach the
// parsers behind them; even ones test the checksums themselves.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_files.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/map_file.h"
#include "recompute_checksums.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size > 0 && (data[0] & 1) != 0) {
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
