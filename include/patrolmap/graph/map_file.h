// The map file: one versioned binary file per patrol series holding the graph,
// the key-frame thumbnails, features and bag-of-words vectors, so a later
// flight can be matched without the original logs.
//
//   8 bytes  magic "PMMAP\0\0\0"
//   u32      format version
//   u32      section count
//   sections tag (4 bytes), u64 payload length, u64 checksum of the payload, payload
//            NODE: per node flight, time, frame, thumbnail, GPS, layout, heading
//            EDGE: per edge the two nodes, kind and verification scores
//            FEAT: per node feature positions, descriptors (float, 8-bit or packed 4-bit rows,
//                  vocab/descriptors.h) and BoW vector (format version 8; before it, 24-byte
//                  keypoint records, of which only the position is read)
//            PTRL: per patrol its camera, views, object map and evidence grid
//                  (format version 2; version 1 files have no PTRL and still load)
// Saving is atomic (temporary file, fsync, rename): a crash never leaves a
// half-written map. Loading a truncated, corrupt, foreign or newer file fails
// with a message naming the file and the problem.
#pragma once

#include <string>

#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

Status SaveMap(const TopoMap& map, const std::string& path);
Status LoadMap(const std::string& path, TopoMap* map);

}  // namespace patrolmap::graph
