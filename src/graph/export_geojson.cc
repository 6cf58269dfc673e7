// GeoJSON (RFC 7946, [longitude, latitude]): a point per node with GPS, each flight's GPS track as a line, a
// line per loop closure.
#include <nlohmann/json.hpp>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

nlohmann::json LonLat(const Eigen::Vector2d& latitude_longitude) {
  return {latitude_longitude.y(), latitude_longitude.x()};
}

}  // namespace

std::string ToGeoJson(const TopoMap& map) {
  nlohmann::json features = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    if (!n.gps) continue;
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", LonLat(*n.gps)}}},
                        {"properties", {{"node", i}, {"flight", n.flight}, {"timestamp_ns", n.timestamp_ns}}}});
  }
  const std::vector<std::string> flights = map.Flights();
  const std::vector<std::vector<Eigen::Vector2d>> tracks = FlightTracks(map);
  for (std::size_t f = 0; f < tracks.size(); ++f) {
    if (tracks[f].size() < 2) continue;
    nlohmann::json line = nlohmann::json::array();
    for (const Eigen::Vector2d& fix : tracks[f]) line.push_back(LonLat(fix));
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "LineString"}, {"coordinates", line}}},
                        {"properties", {{"flight", flights[f]}, {"kind", "path"}}}});
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != EdgeKind::kLoopClosure || !map.node(e.a).gps || !map.node(e.b).gps) continue;
    features.push_back(
        {{"type", "Feature"},
         {"geometry",
          {{"type", "LineString"}, {"coordinates", {LonLat(*map.node(e.a).gps), LonLat(*map.node(e.b).gps)}}}},
         {"properties",
          {{"kind", "loop_closure"}, {"query_node", e.a}, {"matched_node", e.b}, {"inliers", e.data.inliers}}}});
  }
  return nlohmann::json({{"type", "FeatureCollection"}, {"features", features}})
             .dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
         "\n";
}

}  // namespace patrolmap::graph
