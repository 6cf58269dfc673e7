// Exports of the topological map for the tools people already use, one file per format (export_*.cc).
//  - GraphML (NetworkX, Gephi, yEd) with typed attributes at full precision
//    (17 significant digits: Boost's write_graphml keeps 6, which loses metres
//    of a latitude);
//  - DOT for Graphviz (loop closures dashed and green);
//  - JSON in NetworkX's node-link form ("nodes", "links"), schema
//    "patrolmap.map/1" in the graph attributes;
//  - SVG of the layout.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

std::string ToGraphML(const TopoMap& map);
std::string ToDot(const TopoMap& map);
std::string ToJson(const TopoMap& map);
// Ground-truth verdicts for the SVG, as `patrolmap eval` decides them.
struct SvgTruth {
  std::vector<bool> loop_closure_correct;   // per loop-closure edge, in Edges() order
  std::vector<std::pair<int, int>> missed;  // node pairs of the same place that no closure joins
};

// A picture like the paper's Fig. 5 from the layout: each flight's path in its
// own colour, numbered nodes, loop closures dashed. Without truth they are
// green; with it correct ones are green, false ones red and missed ones blue.
std::string ToSvg(const TopoMap& map, const SvgTruth* truth = nullptr);
// GeoJSON (RFC 7946: [longitude, latitude]) and KML of the nodes with GPS:
// a point per node, a line per flight, a line per loop closure. Only for maps
// whose nodes have GPS positions (HasGps).
bool HasGps(const TopoMap& map);
// The verified matches of one loop closure, in its two nodes' thumbnail pixels: x, y in the first node's
// (the edge's a), then x, y in the second's (pipeline::MatchClosures).
struct ClosureMatches {
  std::vector<std::array<float, 4>> pairs;
};

// One self-contained HTML page (no network at view time): the layout picture, fitted to the window, pan by
// dragging and zoom with the wheel, the legend beside it. Clicking a node shows its key-frame thumbnail
// (embedded as PNG), flight, time and loop closures; clicking a loop closure shows both key frames side by
// side with its verified matches drawn (`matches`: one per closure in Edges() order, or null). Node 0 is shown
// at first, or the one the address names (map.html#node=3, map.html#closure=1). When the page has initialised, <body>
// carries data-ready="N nodes, M loop closures".
std::string ToHtml(const TopoMap& map, const SvgTruth* truth = nullptr,
                   const std::vector<ClosureMatches>* matches = nullptr);
std::string ToGeoJson(const TopoMap& map);
std::string ToKml(const TopoMap& map);

// Helpers the change report shares: XML/HTML escaping, Base64, an image as a
// PNG data URI ("" for an empty image).
std::string EscapeXml(const std::string& text);
std::string Base64(const std::vector<unsigned char>& bytes);
std::string PngDataUri(const cv::Mat& image);

}  // namespace patrolmap::graph
