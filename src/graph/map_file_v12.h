// The map file as formats 1 to 12 wrote it, before the map moved into an SQLite database (map_file.h): one binary
// file of checksummed sections.
//
//   8 bytes  magic "PMMAP\0\0\0"
//   u32      format version
//   u32      section count
//   sections tag (4 bytes), u64 payload length, u64 checksum of the payload, payload
//            NODE: per node flight, time, frame, thumbnail, GPS, layout, heading
//            EDGE: per edge the two nodes, kind and verification scores
//            FEAT: per node feature positions, descriptors and BoW vector (format 8 on; before it, 24-byte
//                  keypoint records, of which only the position is read)
//            PTRL: per patrol its camera, views, object map and evidence grid (format 2 on)
//            VOCB: the vocabulary's fingerprint and name (format 3 on)
// LoadMap reads these files (a migration: the next save writes the database); the writer is kept so the reader
// of every older version stays tested.
#pragma once

#include <cstdint>
#include <string>

#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

inline constexpr char kLegacyMagic[8] = {'P', 'M', 'M', 'A', 'P', '\0', '\0', '\0'};
inline constexpr std::uint32_t kLegacyVersion = 12;

// Parses the bytes of a legacy map file read from `path` (named in messages).
Status ParseLegacyMap(const std::string& path, const std::string& bytes, TopoMap* map);
// Writes `map` as format 12 (atomically); every record must be whole.
Status SaveLegacyMap(const TopoMap& map, const std::string& path);

}  // namespace patrolmap::graph
