// DOT for Graphviz: loop closures dashed and green.
#include <sstream>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

std::string EscapeDot(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

std::string ToDot(const TopoMap& map) {
  std::ostringstream out;
  out << "graph patrolmap {\n  node [shape=circle, fontsize=10];\n";
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    out << "  n" << i << " [label=\"" << i << "\", flight=\"" << EscapeDot(n.flight) << "\", frame=" << n.frame_index
        << "];\n";
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    out << "  n" << e.a << " -- n" << e.b;
    if (e.data.kind == EdgeKind::kLoopClosure) {
      out << " [kind=loop_closure, style=dashed, color=\"#2a9d3a\", inliers=" << e.data.inliers << "]";
    }
    out << ";\n";
  }
  out << "}\n";
  return out.str();
}

}  // namespace patrolmap::graph
