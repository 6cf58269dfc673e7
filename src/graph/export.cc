#include "patrolmap/graph/export.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

namespace patrolmap::graph {
namespace {

std::string Precise(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

}  // namespace

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Base64(const std::vector<unsigned char>& bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned value =
        (bytes[i] << 16) | ((i + 1 < bytes.size() ? bytes[i + 1] : 0) << 8) | (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += kAlphabet[(value >> 18) & 63];
    out += kAlphabet[(value >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(value >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[value & 63] : '=';
  }
  return out;
}

std::string PngDataUri(const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (image.empty() || !cv::imencode(".png", image, png)) return "";
  return "data:image/png;base64," + Base64(png);
}

namespace {

std::string EscapeDot(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

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
    const NodeData& n = map.node(i);
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

std::string ToDot(const TopoMap& map) {
  std::ostringstream out;
  out << "graph patrolmap {\n  node [shape=circle, fontsize=10];\n";
  for (int i = 0; i < map.node_count(); ++i) {
    const NodeData& n = map.node(i);
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

std::string ToJson(const TopoMap& map) {
  nlohmann::json nodes = nlohmann::json::array(), links = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const NodeData& n = map.node(i);
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

bool HasGps(const TopoMap& map) {
  for (int i = 0; i < map.node_count(); ++i) {
    if (map.node(i).gps) return true;
  }
  return false;
}

namespace {

nlohmann::json LonLat(const NodeData& node) { return {node.gps->y(), node.gps->x()}; }

// Nodes of each flight that have GPS, in order.
std::vector<std::vector<int>> FlightPaths(const TopoMap& map) {
  const std::vector<std::string> flights = map.Flights();
  std::vector<std::vector<int>> paths(flights.size());
  for (int i = 0; i < map.node_count(); ++i) {
    if (!map.node(i).gps) continue;
    paths[std::find(flights.begin(), flights.end(), map.node(i).flight) - flights.begin()].push_back(i);
  }
  return paths;
}

}  // namespace

std::string ToGeoJson(const TopoMap& map) {
  nlohmann::json features = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const NodeData& n = map.node(i);
    if (!n.gps) continue;
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", LonLat(n)}}},
                        {"properties", {{"node", i}, {"flight", n.flight}, {"timestamp_ns", n.timestamp_ns}}}});
  }
  const std::vector<std::string> flights = map.Flights();
  const std::vector<std::vector<int>> paths = FlightPaths(map);
  for (std::size_t f = 0; f < paths.size(); ++f) {
    if (paths[f].size() < 2) continue;
    nlohmann::json line = nlohmann::json::array();
    for (int i : paths[f]) line.push_back(LonLat(map.node(i)));
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "LineString"}, {"coordinates", line}}},
                        {"properties", {{"flight", flights[f]}, {"kind", "path"}}}});
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != EdgeKind::kLoopClosure || !map.node(e.a).gps || !map.node(e.b).gps) continue;
    features.push_back(
        {{"type", "Feature"},
         {"geometry", {{"type", "LineString"}, {"coordinates", {LonLat(map.node(e.a)), LonLat(map.node(e.b))}}}},
         {"properties",
          {{"kind", "loop_closure"}, {"query_node", e.a}, {"matched_node", e.b}, {"inliers", e.data.inliers}}}});
  }
  return nlohmann::json({{"type", "FeatureCollection"}, {"features", features}})
             .dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
         "\n";
}

std::string ToKml(const TopoMap& map) {
  std::ostringstream out;
  const auto coordinate = [](const NodeData& n) { return Precise(n.gps->y()) + "," + Precise(n.gps->x()) + ",0"; };
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
      << "<name>patrolmap</name>\n";
  for (int i = 0; i < map.node_count(); ++i) {
    if (!map.node(i).gps) continue;
    out << "<Placemark><name>" << i << "</name><description>" << EscapeXml(map.node(i).flight)
        << "</description><Point><coordinates>" << coordinate(map.node(i)) << "</coordinates></Point></Placemark>\n";
  }
  const std::vector<std::string> flights = map.Flights();
  const std::vector<std::vector<int>> paths = FlightPaths(map);
  for (std::size_t f = 0; f < paths.size(); ++f) {
    if (paths[f].size() < 2) continue;
    out << "<Placemark><name>" << EscapeXml(flights[f]) << "</name><LineString><coordinates>";
    for (int i : paths[f]) out << coordinate(map.node(i)) << " ";
    out << "</coordinates></LineString></Placemark>\n";
  }
  out << "</Document>\n</kml>\n";
  return out.str();
}

std::string ToSvg(const TopoMap& map, const SvgTruth* truth) {
  constexpr double kSize = 800.0, kMargin = 40.0;
  Eigen::Vector2d low(0, 0), high(1, 1);
  for (int i = 0; i < map.node_count(); ++i) {
    low = i == 0 ? map.node(i).layout : low.cwiseMin(map.node(i).layout);
    high = i == 0 ? map.node(i).layout : high.cwiseMax(map.node(i).layout);
  }
  const double span = std::max({high.x() - low.x(), high.y() - low.y(), 1e-6});
  const double scale = (kSize - 2 * kMargin) / span;
  const auto x = [&](int i) { return Precise(kMargin + (map.node(i).layout.x() - low.x()) * scale); };
  const auto y = [&](int i) { return Precise(kSize - kMargin - (map.node(i).layout.y() - low.y()) * scale); };
  // Flight colours stay clear of the verdict colours (green, red, blue).
  const char* colours[] = {"#374151", "#d97706", "#7c3aed", "#0f766e", "#a16207"};
  const std::vector<std::string> flights = map.Flights();
  std::ostringstream out;
  out << "<?xml version='1.0' encoding='UTF-8'?>\n<svg xmlns='http://www.w3.org/2000/svg' width='" << kSize
      << "' height='" << kSize << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n";
  std::size_t closure_index = 0;
  for (const TopoMap::Edge& e : map.Edges()) {
    const bool closure = e.data.kind == EdgeKind::kLoopClosure;
    const std::size_t flight = std::find(flights.begin(), flights.end(), map.node(e.a).flight) - flights.begin();
    std::string colour = colours[flight % 5];
    if (closure) {
      const bool correct = truth == nullptr || truth->loop_closure_correct.at(closure_index++);
      colour = correct ? "#16a34a" : "#dc2626";
    }
    out << "<line x1='" << x(e.a) << "' y1='" << y(e.a) << "' x2='" << x(e.b) << "' y2='" << y(e.b) << "' stroke='"
        << colour << "' stroke-width='" << (closure ? 2 : 3) << "'" << (closure ? " stroke-dasharray='6 4'" : "")
        << "/>\n";
  }
  for (const auto& [a, b] : truth != nullptr ? truth->missed : std::vector<std::pair<int, int>>{}) {
    out << "<line x1='" << x(a) << "' y1='" << y(a) << "' x2='" << x(b) << "' y2='" << y(b)
        << "' stroke='#2563eb' stroke-width='2' stroke-dasharray='2 3'/>\n";
  }
  for (int i = 0; i < map.node_count(); ++i) {
    const std::size_t flight = std::find(flights.begin(), flights.end(), map.node(i).flight) - flights.begin();
    out << "<circle class='node' data-node='" << i << "' cx='" << x(i) << "' cy='" << y(i) << "' r='6' fill='"
        << colours[flight % 5] << "'/><text x='" << x(i) << "' y='" << y(i) << "' dx='8' dy='-8' font-size='11'>" << i
        << "</text>\n";
  }
  for (std::size_t f = 0; f < flights.size(); ++f) {
    out << "<text x='10' y='" << 18 + 16 * f << "' font-size='12' fill='" << colours[f % 5] << "'>"
        << EscapeXml(flights[f]) << "</text>\n";
  }
  const std::size_t legend = 18 + 16 * flights.size();
  out << "<text x='10' y='" << legend << "' font-size='12' fill='#16a34a'>"
      << (truth ? "correct loop closure" : "loop closure") << "</text>\n";
  if (truth != nullptr) {
    out << "<text x='10' y='" << legend + 16 << "' font-size='12' fill='#dc2626'>false loop closure</text>\n"
        << "<text x='10' y='" << legend + 32 << "' font-size='12' fill='#2563eb'>missed loop closure</text>\n";
  }
  out << "</svg>\n";
  return out.str();
}

namespace {

// JSON to embed in an HTML <script> element: '<', '>' and '&' become their JSON escapes (\u003c ...), so no
// string from a log can end the element early (a flight id "x</script><img ...>").
std::string JsonForScript(const nlohmann::json& value) {
  const std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

nlohmann::json NodeDetails(const TopoMap& map) {
  nlohmann::json nodes = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const NodeData& n = map.node(i);
    nodes.push_back({{"flight", n.flight},
                     {"time_s", NsToSeconds(n.timestamp_ns)},
                     {"frame", n.frame_index},
                     {"thumbnail", PngDataUri(n.thumbnail)},
                     {"closures", nlohmann::json::array()}});
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != EdgeKind::kLoopClosure) continue;
    nodes[e.a]["closures"].push_back({{"node", e.b}, {"inliers", e.data.inliers}});
    nodes[e.b]["closures"].push_back({{"node", e.a}, {"inliers", e.data.inliers}});
  }
  return nodes;
}

constexpr char kPageScript[] = R"(
const nodes = JSON.parse(document.getElementById('nodes').textContent);
const svg = document.querySelector('#map svg');
let box = svg.viewBox.baseVal;
let drag = null;
svg.addEventListener('mousedown', e => { drag = {x: e.clientX, y: e.clientY}; });
window.addEventListener('mouseup', () => { drag = null; });
svg.addEventListener('mousemove', e => {
  if (!drag) return;
  const k = box.width / svg.clientWidth;
  box.x -= (e.clientX - drag.x) * k; box.y -= (e.clientY - drag.y) * k;
  drag = {x: e.clientX, y: e.clientY};
});
svg.addEventListener('wheel', e => {
  e.preventDefault();
  const f = e.deltaY > 0 ? 1.15 : 1 / 1.15;
  box.x += box.width * (1 - f) / 2; box.y += box.height * (1 - f) / 2; box.width *= f; box.height *= f;
});
function show(i) {
  const n = nodes[i];
  document.getElementById('title').textContent = 'node ' + i + ' - ' + n.flight + ', ' + n.time_s.toFixed(1) + ' s, frame ' + n.frame;
  document.getElementById('thumb').src = n.thumbnail;
  document.getElementById('closures').textContent = n.closures.length ?
      'loop closures: ' + n.closures.map(c => 'node ' + c.node + ' (' + c.inliers + ' inliers)').join(', ') : 'no loop closure';
}
document.querySelectorAll('#map .node').forEach(c => c.addEventListener('click', () => show(+c.dataset.node)));
if (nodes.length) show(0);
document.body.dataset.ready = nodes.length + ' nodes';
)";

}  // namespace

std::string ToHtml(const TopoMap& map, const SvgTruth* truth) {
  std::string svg = ToSvg(map, truth);
  svg = svg.substr(svg.find("<svg"));
  svg.replace(svg.find("<svg"), 4, "<svg viewBox='0 0 800 800'");
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>patrolmap map</title>\n<style>"
      << "body{font-family:sans-serif;margin:0;display:flex;height:100vh}#map{flex:1;border-right:1px solid #ccc}"
      << "#map svg{width:100%;height:100%;cursor:grab}#side{width:340px;padding:12px}#thumb{width:320px;"
      << "image-rendering:pixelated;background:#eee;min-height:100px}.node{cursor:pointer}</style></head>\n<body>\n"
      << "<div id='map'>" << svg << "</div>\n<div id='side'><h3>patrolmap</h3><p>" << map.node_count() << " nodes, "
      << map.loop_closure_count() << " loop closures, " << map.Flights().size()
      << " flight(s). Drag to pan, wheel to zoom, click a node.</p><p id='title'></p><img id='thumb' alt=''>"
      << "<p id='closures'></p></div>\n<script type='application/json' id='nodes'>" << JsonForScript(NodeDetails(map))
      << "</script>\n<script>" << kPageScript << "</script>\n</body></html>\n";
  return out.str();
}

}  // namespace patrolmap::graph
