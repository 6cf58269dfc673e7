// GraphML (NetworkX, Gephi, yEd) with typed attributes at full precision.
#include <sstream>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

void GraphMLKeys(std::ostringstream* out) {
  const char* keys[][4] = {{"flight", "node", "string", "flight"},
                           {"time", "node", "long", "timestamp_ns"},
                           {"frame", "node", "long", "frame_index"},
                           {"lat", "node", "double", "latitude"},
                           {"lon", "node", "double", "longitude"},
                           {"x", "node", "double", "x"},
                           {"y", "node", "double", "y"},
                           {"kind", "edge", "string", "kind"},
                           {"bow", "edge", "double", "bow_score"},
                           {"frac", "edge", "double", "matched_fraction"},
                           {"inl", "edge", "int", "inliers"}};
  for (const auto& key : keys) {
    *out << "  <key id=\"" << key[0] << "\" for=\"" << key[1] << "\" attr.name=\"" << key[3] << "\" attr.type=\""
         << key[2] << "\"/>\n";
  }
}

}  // namespace

std::string ToGraphML(const TopoMap& map) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<graphml xmlns=\"http://graphml.graphdrawing.org/xmlns\">\n";
  GraphMLKeys(&out);
  out << "  <graph id=\"patrolmap\" edgedefault=\"undirected\">\n";
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    out << "    <node id=\"n" << i << "\"><data key=\"flight\">" << EscapeXml(n.flight) << "</data><data key=\"time\">"
        << n.timestamp_ns << "</data><data key=\"frame\">" << n.frame_index << "</data>";
    if (n.gps)
      out << "<data key=\"lat\">" << Precise(n.gps->x()) << "</data><data key=\"lon\">" << Precise(n.gps->y())
          << "</data>";
    out << "<data key=\"x\">" << Precise(n.layout.x()) << "</data><data key=\"y\">" << Precise(n.layout.y())
        << "</data></node>\n";
  }
  int index = 0;
  for (const TopoMap::Edge& e : map.Edges()) {
    out << "    <edge id=\"e" << index++ << "\" source=\"n" << e.a << "\" target=\"n" << e.b << "\"><data key=\"kind\">"
        << ToString(e.data.kind) << "</data><data key=\"bow\">" << Precise(e.data.bow_score)
        << "</data><data key=\"frac\">" << Precise(e.data.matched_fraction) << "</data><data key=\"inl\">"
        << e.data.inliers << "</data></edge>\n";
  }
  out << "  </graph>\n</graphml>\n";
  return out.str();
}

}  // namespace patrolmap::graph
