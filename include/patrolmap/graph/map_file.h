// The map file: one SQLite 3 database (map format 13) holding the graph, the key frames' thumbnails, features and
// bag-of-words vectors, and what each patrol keeps for change detection, so a later flight can be matched and
// compared without the original logs. One file a user can copy; `sqlite3 map.pmap .schema` shows the tables:
//
//   map_info(key, value)   format "patrolmap.map", version, vocabulary_fingerprint (hex), vocabulary_name
//   nodes                  one row per key location: id (0, 1, ...), flight, timestamp_ns, frame_index, latitude and
//                          longitude (NULL without GPS), layout_x, layout_y, heading, thumbnail and features (blobs)
//   edges                  one row per edge in insertion order: node_a, node_b, kind ('traversal' or
//                          'loop_closure'), bow_score, matched_fraction, inliers, log_nfa
//   patrols                one row per patrol record, in the map's order: flight, the camera (fx, fy, cx, cy,
//                          width, height, distortion), depth_source, pose_source, timed, source (the log),
//                          source_digest, views (blob of poses), voxel_size, evicted_voxels
//   objects                the patrol's object map: patrol, position, id, site_object, label, confidence,
//                          detections, confirmed, x, y, z (centroid), first_seen_ns, last_seen_ns, shape (blob)
//   grids                  the patrol's evidence grid: patrol, voxels (blob of 16-byte voxels, ascending x, y, z)
//   route_frames           the frames kept along its route: patrol, position, timestamp_ns, frame_index, pose
//                          (x, y, z, qw, qx, qy, qz; NULL without), latitude, longitude, jpeg
//
// Blobs hold little-endian values (graph/map_codec.h). A save writes a temporary file beside the map and renames
// it over the map once it is complete and on disk, so a crash or kill at any moment leaves the previous map
// whole. Loading a truncated, corrupt, foreign or newer file fails with a message naming the file and the problem;
// maps of formats 1 to 12 (one binary file before the database) load too, and save as the database.
#pragma once

#include <string>

#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

// How much of the patrol records a load reads. kAll: everything. kLatest: what a new patrol is compared with, the
// latest state of the site: the last flight's record whole, and of each earlier record its nodes, objects, views
// and the voxels of its grid no later patrol observed, without route frames (PatrolRecord::partial); SaveMapOnto
// keeps the rest in the file. So a patrol's memory and load time grow with the site, not with the patrols flown.
enum class PatrolDetail { kAll, kLatest };

// How much of each patrol a map keeps, so that it grows with the area of the site rather than with the patrols
// flown (the map.* keys of the configuration).
struct MapRetention {
  // The latest patrols kept whole, for comparing, aligning and diffing. Each older patrol is archived
  // (PatrolRecord::archived): its evidence grid keeps only the voxels no later patrol observed, so the grids of
  // the map together hold each voxel of the site once, and its route frames one every archive_frame_interval_s;
  // its nodes, objects and views stay as they were.
  int whole_patrols = 2;
  double archive_frame_interval_s = 10.0;  // [s]; 0 keeps every frame of an archived patrol

  bool IsValid(std::string* error) const;
};

// Writes `map` whole to `path` (then archives what `retention` says); every patrol record must be whole.
Status SaveMap(const TopoMap& map, const std::string& path, const MapRetention& retention = MapRetention());
Status LoadMap(const std::string& path, TopoMap* map, PatrolDetail detail = PatrolDetail::kAll);
// Writes `map`, loaded from the map file `base` and grown since (new nodes, edges and patrol records appended, the
// layout and site objects renumbered), to `path` as a copy of `base` with the changes applied in one transaction:
// no record already in `base` is read or rewritten but to archive it. A `base` of format 12 or older is saved whole.
Status SaveMapOnto(const TopoMap& map, const std::string& base, const std::string& path,
                   const MapRetention& retention = MapRetention());

}  // namespace patrolmap::graph
