// SVG of the layout, like the paper's Fig. 5: each flight's path in its own colour, numbered nodes (the ids
// of nodes.csv), loop closures as dashed curves, judged by the truth when there is one.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

constexpr double kWidth = 800.0;                // SVG user units across
constexpr double kMargin = 30.0;                // around the nodes
constexpr double kNodeR = 6.0;                  // node radius
constexpr double kCoincidentPx = 2.5 * kNodeR;  // closer nodes: a closure between them is a ring

// Layout coordinates to the drawing's (y down), keeping the aspect, below a band `top` high (the legend's);
// the height follows the layout.
class Frame {
 public:
  Frame(const TopoMap& map, double top) : top_(top) {
    for (int i = 0; i < map.node_count(); ++i) {
      low_ = i == 0 ? map.node(i).layout : low_.cwiseMin(map.node(i).layout);
      high_ = i == 0 ? map.node(i).layout : high_.cwiseMax(map.node(i).layout);
    }
    const Eigen::Vector2d span = (high_ - low_).cwiseMax(1e-6);
    scale_ = (kWidth - 2 * kMargin) / span.x();
    const double drawing = std::clamp(span.y() * scale_ + 2 * kMargin, 200.0, 1.5 * kWidth);
    scale_ = std::min(scale_, (drawing - 2 * kMargin) / span.y());
    height_ = top + drawing;
    offset_ = Eigen::Vector2d(kWidth - span.x() * scale_, drawing - span.y() * scale_) / 2.0;
  }
  Eigen::Vector2d operator()(const Eigen::Vector2d& layout) const {
    return {offset_.x() + (layout.x() - low_.x()) * scale_, top_ + offset_.y() + (high_.y() - layout.y()) * scale_};
  }
  double height() const { return height_; }

 private:
  double top_;
  Eigen::Vector2d low_ = Eigen::Vector2d::Zero(), high_ = Eigen::Vector2d::Ones();
  Eigen::Vector2d offset_;
  double scale_ = 1.0, height_ = kWidth;
};

std::string Number(double value) {
  std::ostringstream out;
  out.precision(1);
  out << std::fixed << value;
  return out.str();
}

std::size_t FlightIndex(const std::vector<std::string>& flights, const std::string& flight) {
  return std::find(flights.begin(), flights.end(), flight) - flights.begin();
}

// A closure: a ring around coincident nodes (wider for each further ring there), else a curve bowed to one
// side so it stays clear of the traversal between the same nodes.
std::string ClosureShape(const Eigen::Vector2d& a, const Eigen::Vector2d& b, int ring) {
  if ((a - b).norm() < kCoincidentPx) {
    const Eigen::Vector2d c = (a + b) / 2.0;
    return "<circle cx='" + Number(c.x()) + "' cy='" + Number(c.y()) + "' r='" + Number(kNodeR + 5 + 5 * ring) +
           "' fill='none'";
  }
  const Eigen::Vector2d mid = (a + b) / 2.0, d = b - a;
  const Eigen::Vector2d control = mid + Eigen::Vector2d(-d.y(), d.x()) * 0.18;
  return "<path d='M" + Number(a.x()) + "," + Number(a.y()) + " Q" + Number(control.x()) + "," + Number(control.y()) +
         " " + Number(b.x()) + "," + Number(b.y()) + "' fill='none'";
}

void Traversals(const TopoMap& map, const Frame& frame, std::ostringstream* out) {
  const std::vector<std::string> flights = map.Flights();
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind == EdgeKind::kLoopClosure) continue;
    const Eigen::Vector2d a = frame(map.node(e.a).layout), b = frame(map.node(e.b).layout);
    *out << "<line x1='" << Number(a.x()) << "' y1='" << Number(a.y()) << "' x2='" << Number(b.x()) << "' y2='"
         << Number(b.y()) << "' stroke='" << kFlightColours[FlightIndex(flights, map.node(e.a).flight) % 5]
         << "' stroke-width='3'/>\n";
  }
}

void Closures(const TopoMap& map, const Frame& frame, const SvgTruth* truth, std::ostringstream* out) {
  std::map<int, int> rings;  // per node: rings drawn around it
  int index = 0;
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != EdgeKind::kLoopClosure) continue;
    const bool correct = truth == nullptr || truth->loop_closure_correct.at(index);
    const Eigen::Vector2d a = frame(map.node(e.a).layout), b = frame(map.node(e.b).layout);
    const std::string shape = ClosureShape(a, b, (a - b).norm() < kCoincidentPx ? rings[e.a]++ : 0);
    *out << "<g class='closure' data-edge='" << index << "'>" << shape << " stroke='"
         << (correct ? "#16a34a" : "#dc2626") << "' stroke-width='2.5' stroke-dasharray='6 4'/>" << shape
         << " stroke='transparent' stroke-width='10'/><title>loop closure: node " << e.a << " and node " << e.b << ", "
         << e.data.inliers << " inliers</title></g>\n";
    ++index;
  }
  for (const auto& [a, b] : truth != nullptr ? truth->missed : std::vector<std::pair<int, int>>{}) {
    const Eigen::Vector2d p = frame(map.node(a).layout), q = frame(map.node(b).layout);
    *out << "<line x1='" << Number(p.x()) << "' y1='" << Number(p.y()) << "' x2='" << Number(q.x()) << "' y2='"
         << Number(q.y()) << "' stroke='#2563eb' stroke-width='2' stroke-dasharray='2 3'/>\n";
  }
}

void Nodes(const TopoMap& map, const Frame& frame, std::ostringstream* out) {
  const std::vector<std::string> flights = map.Flights();
  for (int i = 0; i < map.node_count(); ++i) {
    const Eigen::Vector2d p = frame(map.node(i).layout);
    *out << "<circle class='node' data-node='" << i << "' cx='" << Number(p.x()) << "' cy='" << Number(p.y()) << "' r='"
         << kNodeR << "' fill='" << kFlightColours[FlightIndex(flights, map.node(i).flight) % 5] << "'/><text x='"
         << Number(p.x()) << "' y='" << Number(p.y()) << "' dx='8' dy='-8' font-size='11'>" << i << "</text>\n";
  }
}

void SvgLegend(const TopoMap& map, const SvgTruth* truth, std::ostringstream* out) {
  const std::vector<std::string> flights = map.Flights();
  for (std::size_t f = 0; f < flights.size(); ++f) {
    *out << "<text x='10' y='" << 18 + 16 * f << "' font-size='12' fill='" << kFlightColours[f % 5] << "'>"
         << EscapeXml(flights[f]) << "</text>\n";
  }
  const std::size_t legend = 18 + 16 * flights.size();
  *out << "<text x='10' y='" << legend << "' font-size='12' fill='#16a34a'>"
       << (truth ? "correct loop closure" : "loop closure") << "</text>\n";
  if (truth != nullptr) {
    *out << "<text x='10' y='" << legend + 16 << "' font-size='12' fill='#dc2626'>false loop closure</text>\n"
         << "<text x='10' y='" << legend + 32 << "' font-size='12' fill='#2563eb'>missed loop closure</text>\n";
  }
}

}  // namespace

std::string SvgDrawing(const TopoMap& map, const SvgTruth* truth, bool legend) {
  const double legend_lines = static_cast<double>(map.Flights().size()) + (truth != nullptr ? 3 : 1);
  const Frame frame(map, legend ? 16.0 * legend_lines + 8.0 : 0.0);
  std::ostringstream out;
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='" << Number(frame.height())
      << "' viewBox='0 0 " << kWidth << " " << Number(frame.height())
      << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n";
  Traversals(map, frame, &out);
  Closures(map, frame, truth, &out);
  Nodes(map, frame, &out);
  if (legend) SvgLegend(map, truth, &out);
  out << "</svg>\n";
  return out.str();
}

std::string ToSvg(const TopoMap& map, const SvgTruth* truth) {
  return "<?xml version='1.0' encoding='UTF-8'?>\n" + SvgDrawing(map, truth, true);
}

}  // namespace patrolmap::graph
