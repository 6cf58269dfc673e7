// JSON in NetworkX's node-link form.
#include <sstream>

#include <nlohmann/json.hpp>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
std::string ToJson(const TopoMap& map) {
  nlohmann::json nodes = nlohmann::json::array(), links = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    nlohmann::json node = {{"id", i},
                           {"flight", n.flight},
                           {"timestamp_ns", n.timestamp_ns},
                           {"frame_index", n.frame_index},
                           {"layout", {n.layout.x(), n.layout.y()}}};
    node["gps"] = n.gps ? nlohmann::json{n.gps->x(), n.gps->y()} : nlohmann::json(nullptr);
    nodes.push_back(node);
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    links.push_back({{"source", e.a},
                     {"target", e.b},
                     {"kind", ToString(e.data.kind)},
                     {"bow_score", e.data.bow_score},
                     {"matched_fraction", e.data.matched_fraction},
                     {"inliers", e.data.inliers}});
  }
  const nlohmann::json document = {{"directed", false},
                                   {"multigraph", true},
                                   {"graph", {{"schema", "patrolmap.map/1"}, {"flights", map.Flights()}}},
                                   {"nodes", nodes},
                                   {"links", links}};
  return document.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace patrolmap::graph
