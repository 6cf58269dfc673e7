#include "patrolmap/pipeline/closure_matches.h"

namespace patrolmap::pipeline {
namespace {

// Thumbnail pixels per feature-image pixel of the node; 0 when its flight's feature image width is unknown.
double ThumbnailScale(const graph::TopoMap& map, int node) {
  const PatrolRecord* record = map.Patrol(map.node(node).flight);
  if (record == nullptr || record->feature_image_width <= 0) return 0.0;
  return static_cast<double>(map.node(node).thumbnail.cols) / record->feature_image_width;
}

}  // namespace

std::vector<graph::ClosureMatches> MatchClosures(const graph::TopoMap& map, const place::PlaceOptions& options) {
  std::vector<graph::ClosureMatches> closures;
  std::vector<std::pair<int, int>> inliers;
  for (const graph::TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != graph::EdgeKind::kLoopClosure) continue;
    graph::ClosureMatches& matches = closures.emplace_back();
    const double scale_a = ThumbnailScale(map, e.a), scale_b = ThumbnailScale(map, e.b);
    if (scale_a <= 0.0 || scale_b <= 0.0) continue;
    const KeyFrameNode &a = map.node(e.a), &b = map.node(e.b);
    place::VerifyPair(options, a.points, a.descriptors, b.points, b.descriptors, &inliers);
    for (const auto& [i, j] : inliers) {
      matches.pairs.push_back({static_cast<float>(a.points[i].x * scale_a), static_cast<float>(a.points[i].y * scale_a),
                               static_cast<float>(b.points[j].x * scale_b),
                               static_cast<float>(b.points[j].y * scale_b)});
    }
  }
  return closures;
}

}  // namespace patrolmap::pipeline
