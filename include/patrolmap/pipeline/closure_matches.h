// The verified matches of a map's loop closures, for the map viewer (graph::ToHtml): each closure's two
// stored key frames matched again with the place stage's verification (place::VerifyPair, without the
// direct-index groups), its fundamental-matrix inliers scaled to the nodes' thumbnails.
#pragma once

#include <vector>

#include "patrolmap/graph/export.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/place/place_recognizer.h"

namespace patrolmap::pipeline {

// One per loop closure, in Edges() order; empty pairs where a flight's feature image width is unknown.
std::vector<graph::ClosureMatches> MatchClosures(const graph::TopoMap& map, const place::PlaceOptions& options);

}  // namespace patrolmap::pipeline
