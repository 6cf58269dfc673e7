#include "report_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "patrolmap/core/words.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::change {
namespace {

constexpr double kWidth = 800.0;        // SVG user units across the plan
constexpr double kPad = 30.0;           // around the drawing
constexpr double kMarginM = 4.0;        // world margin around what is drawn [m]
constexpr double kMarkerRadius = 13.0;  // a numbered marker's circle
constexpr double kMarkerGap = 3.0;      // at least this between two markers' circles

// 1, 2 or 5 times a power of ten, at most `limit`.
double NiceStep(double limit) {
  const double power = std::pow(10.0, std::floor(std::log10(limit)));
  for (double f : {5.0, 2.0, 1.0}) {
    if (f * power <= limit) return f * power;
  }
  return power;
}

// World x, y to SVG coordinates (y down): the plan's frame. North up when there is a geo reference.
class PlanFrame {
 public:
  PlanFrame(const std::vector<Eigen::Vector2d>& points, const std::optional<GeoReference>& geo) {
    if (geo) turn_ = geo->rotation;  // world to east-north
    low_ = high_ = Turn(points[0]);
    for (const Eigen::Vector2d& p : points) low_ = low_.cwiseMin(Turn(p)), high_ = high_.cwiseMax(Turn(p));
    low_ -= Eigen::Vector2d::Constant(kMarginM), high_ += Eigen::Vector2d::Constant(kMarginM);
    scale_ = (kWidth - 2 * kPad) / std::max(high_.x() - low_.x(), 1.0);
    height_ = std::min(2.0 * kWidth, (high_.y() - low_.y()) * scale_ + 2 * kPad);
    scale_ = std::min(scale_, (height_ - 2 * kPad) / std::max(high_.y() - low_.y(), 1.0));
  }
  Eigen::Vector2d operator()(const Eigen::Vector2d& world) const {
    const Eigen::Vector2d p = Turn(world);
    return {kPad + (p.x() - low_.x()) * scale_, height_ - kPad - (p.y() - low_.y()) * scale_};
  }
  std::string Point(const Eigen::Vector3d& world) const {
    const Eigen::Vector2d p = (*this)(world.head<2>());
    return Fixed(p.x(), 1) + "," + Fixed(p.y(), 1);
  }
  double scale() const { return scale_; }  // SVG units per metre
  double height() const { return height_; }
  double width_m() const { return high_.x() - low_.x(); }

 private:
  Eigen::Vector2d Turn(const Eigen::Vector2d& p) const { return turn_ * p; }
  Eigen::Matrix2d turn_ = Eigen::Matrix2d::Identity();
  Eigen::Vector2d low_, high_;
  double scale_ = 1.0, height_ = kWidth;
};

void Path(const PatrolRecord* record, const PlanFrame& frame, const char* style, std::ostringstream* svg) {
  if (record == nullptr || record->views.size() < 2) return;
  *svg << "<polyline class='path' fill='none' " << style << " points='";
  for (const CameraPoseSample& v : record->views) *svg << frame.Point(v.position) << " ";
  *svg << "'><title>" << graph::EscapeXml(record->flight) << "</title></polyline>\n";
}

void ScaleBar(const PlanFrame& frame, std::ostringstream* svg) {
  const double metres = NiceStep(frame.width_m() / 4.0);
  const double length = metres * frame.scale(), y = frame.height() - 12.0;
  *svg << "<g class='scale'><line x1='" << kPad << "' y1='" << y << "' x2='" << Fixed(kPad + length, 1) << "' y2='" << y
       << "' stroke='#111' stroke-width='3'/><text x='" << Fixed(kPad + length + 6, 1) << "' y='" << y + 4
       << "' font-size='12'>" << Fixed(metres, metres < 1 ? 1 : 0) << " m</text></g>\n";
}

void NorthArrow(const PlanFrame& frame, std::ostringstream* svg) {
  const double x = kWidth - 24.0, y = 40.0;
  *svg << "<g class='north'><path d='M" << x << "," << y - 22 << " L" << x - 8 << "," << y << " L" << x << "," << y - 6
       << " L" << x + 8 << "," << y << " Z' fill='#111'/><text x='" << x - 4 << "' y='" << y + 14
       << "' font-size='13' font-weight='bold'>N</text></g>\n";
  (void)frame;
}

// Lines of equal latitude and longitude, about five across, labelled at the plan's edge.
void Graticule(const PlanFrame& frame, const GeoReference& geo, const std::vector<Eigen::Vector2d>& points,
               std::ostringstream* svg) {
  Eigen::Vector2d low = geo.LatitudeLongitude(Eigen::Vector3d(points[0].x(), points[0].y(), 0.0)), high = low;
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d ll = geo.LatitudeLongitude(Eigen::Vector3d(p.x(), p.y(), 0.0));
    low = low.cwiseMin(ll), high = high.cwiseMax(ll);
  }
  const double step = NiceStep(std::max(high.x() - low.x(), high.y() - low.y()) / 4.0);
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step))));
  *svg << "<g class='graticule' stroke='#d6dde6' stroke-width='1' font-size='17' fill='#52606d'>\n";
  for (int axis = 0; axis < 2; ++axis) {
    for (double v = std::ceil(low[axis] / step) * step; v <= high[axis]; v += step) {
      Eigen::Vector2d a = low, b = high;
      a[axis] = b[axis] = v;
      const Eigen::Vector2d p = frame(geo.WorldOf(a)), q = frame(geo.WorldOf(b));
      *svg << "<line x1='" << Fixed(p.x(), 1) << "' y1='" << Fixed(p.y(), 1) << "' x2='" << Fixed(q.x(), 1) << "' y2='"
           << Fixed(q.y(), 1) << "'/><text stroke='none' x='" << Fixed(p.x() + 3, 1) << "' y='" << Fixed(p.y() - 3, 1)
           << "'>" << Fixed(v, decimals) << (axis == 0 ? "&#176;N" : "&#176;E") << "</text>\n";
    }
  }
  *svg << "</g>\n";
}

// The places both flights saw: the current node's camera position, as a hollow diamond.
void Places(const ChangeReport& report, const graph::TopoMap& map, const PlanFrame& frame, std::ostringstream* svg) {
  const PatrolRecord* current = map.Patrol(report.current_flight);
  if (current == nullptr || current->views.empty()) return;
  for (const PlaceChange& place : report.places) {
    const TimestampNs t = map.node(place.current_node).timestamp_ns;
    const auto view = std::min_element(current->views.begin(), current->views.end(),
                                       [t](const CameraPoseSample& a, const CameraPoseSample& b) {
                                         return std::llabs(a.timestamp_ns - t) < std::llabs(b.timestamp_ns - t);
                                       });
    const Eigen::Vector2d p = frame(view->position.head<2>());
    *svg << "<rect class='place' x='" << Fixed(p.x() - 5, 1) << "' y='" << Fixed(p.y() - 5, 1)
         << "' width='10' height='10' transform='rotate(45 " << Fixed(p.x(), 1) << " " << Fixed(p.y(), 1)
         << ")' fill='white' stroke='#2563eb' stroke-width='2'><title>place seen by both flights: node "
         << place.prior_node << " and node " << place.current_node << "</title></rect>\n";
  }
}

// Where each marker goes (SVG units): at its change's place, or, where that would cover a marker placed before it,
// at the nearest free spot on rings around the place (a leader line then joins the two).
class MarkerLayout {
 public:
  Eigen::Vector2d Place(const Eigen::Vector2d& at) {
    constexpr int kDirections = 12, kRings = 6;
    Eigen::Vector2d spot = at;
    for (int ring = 0; ring <= kRings && Covers(spot); ++ring) {
      for (int k = 0; k < kDirections; ++k) {
        const double angle = 2.0 * M_PI * k / kDirections - M_PI / 2.0;
        spot = at + (ring + 1) * (2.0 * kMarkerRadius + kMarkerGap) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        if (!Covers(spot)) break;
      }
    }
    placed_.push_back(spot);
    return spot;
  }

 private:
  bool Covers(const Eigen::Vector2d& spot) const {
    return std::any_of(placed_.begin(), placed_.end(), [&](const Eigen::Vector2d& other) {
      return (other - spot).norm() < 2.0 * kMarkerRadius + kMarkerGap;
    });
  }
  std::vector<Eigen::Vector2d> placed_;
};

// A leader from a change's place to its marker, when the marker had to move.
void Leader(const Eigen::Vector2d& at, const Eigen::Vector2d& marker, const ChangeItem& item, std::ostringstream* svg) {
  if ((marker - at).norm() < 1e-9) return;
  *svg << "<line x1='" << Fixed(at.x(), 1) << "' y1='" << Fixed(at.y(), 1) << "' x2='" << Fixed(marker.x(), 1)
       << "' y2='" << Fixed(marker.y(), 1) << "' stroke='" << ChangeColour(item) << "' stroke-width='1.5'/><circle cx='"
       << Fixed(at.x(), 1) << "' cy='" << Fixed(at.y(), 1) << "' r='3' fill='" << ChangeColour(item) << "'/>\n";
}

// A change placed by a bearing only: the ray from the camera it lies on, dashed, its number at the far end.
void BearingMarker(const ChangeItem& item, const PlanFrame& frame, MarkerLayout* layout, std::ostringstream* svg) {
  const Eigen::Vector2d o = frame(item.bearing->origin.head<2>()), end = frame(BearingEnd(item).head<2>());
  const Eigen::Vector2d e = layout->Place(end);
  *svg << "<g class='marker bearing' data-id='" << graph::EscapeXml(item.id) << "'><line x1='" << Fixed(o.x(), 1)
       << "' y1='" << Fixed(o.y(), 1) << "' x2='" << Fixed(end.x(), 1) << "' y2='" << Fixed(end.y(), 1) << "' stroke='"
       << ChangeColour(item) << "' stroke-width='2' stroke-dasharray='6 4'/>";
  Leader(end, e, item, svg);
  *svg << "<circle cx='" << Fixed(e.x(), 1) << "' cy='" << Fixed(e.y(), 1) << "' r='" << kMarkerRadius
       << "' fill='white' stroke='" << ChangeColour(item) << "' stroke-width='2'/><text x='" << Fixed(e.x(), 1)
       << "' y='" << Fixed(e.y() + 5, 1) << "' text-anchor='middle' font-size='14' fill='" << ChangeColour(item)
       << "' font-weight='bold'>" << item.number << "</text><title>" << item.number << ": "
       << graph::EscapeXml(item.kind + " " + item.state)
       << ", somewhere along this bearing from the camera (no depth there)</title></g>\n";
}

void Marker(const ChangeItem& item, const PlanFrame& frame, MarkerLayout* layout, std::ostringstream* svg) {
  const Eigen::Vector2d at = frame(item.position->head<2>());
  if (item.from) {
    const Eigen::Vector2d q = frame(item.from->head<2>());
    *svg << "<line x1='" << Fixed(q.x(), 1) << "' y1='" << Fixed(q.y(), 1) << "' x2='" << Fixed(at.x(), 1) << "' y2='"
         << Fixed(at.y(), 1) << "' stroke='" << ChangeColour(item) << "' stroke-width='2' marker-end='url(#arrow)'/>\n";
  }
  const Eigen::Vector2d p = layout->Place(at);
  Leader(at, p, item, svg);
  *svg << "<g class='marker' data-id='" << graph::EscapeXml(item.id) << "' transform='translate(" << Fixed(p.x(), 1)
       << " " << Fixed(p.y(), 1) << ")'><circle r='" << kMarkerRadius << "' fill='" << ChangeColour(item)
       << "' stroke='white' stroke-width='2'/><text text-anchor='middle' dy='5' font-size='14' fill='white' "
          "font-weight='bold'>"
       << item.number << "</text><title>" << item.number << ": " << graph::EscapeXml(item.kind + " " + item.state)
       << " " << graph::EscapeXml(item.label) << "</title></g>\n";
}

}  // namespace

const char* ChangeColour(const ChangeItem& item) {
  if (item.kind == "geometry") return "#7c3aed";
  if (item.kind == "appearance") return "#0891b2";
  if (item.state == "new") return "#16a34a";
  if (item.state == "removed") return "#dc2626";
  return "#ea580c";
}

std::string PlanSvg(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                    const std::optional<GeoReference>& geo) {
  const PatrolRecord* prior = map.Patrol(report.prior_flight);
  const PatrolRecord* current = map.Patrol(report.current_flight);
  std::vector<Eigen::Vector2d> points;
  for (const PatrolRecord* record : {prior, current}) {
    if (record == nullptr) continue;
    for (const CameraPoseSample& v : record->views) points.push_back(v.position.head<2>());
  }
  for (const ChangeItem& item : items) {
    if (item.position) points.push_back(item.position->head<2>());
    if (item.from) points.push_back(item.from->head<2>());
    if (!item.position && item.bearing) points.push_back(BearingEnd(item).head<2>());
  }
  if (points.empty()) return "";
  const PlanFrame frame(points, geo);
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 " << kWidth << " " << Fixed(frame.height(), 0)
      << "' font-family='sans-serif'>\n<defs><marker id='arrow' viewBox='0 0 10 10' refX='9' refY='5' "
         "markerWidth='6' markerHeight='6' orient='auto-start-reverse'><path d='M0,0 L10,5 L0,10 z' "
         "fill='#444'/></marker></defs>\n<rect width='100%' height='100%' fill='#fbfbfa'/>\n";
  if (geo) Graticule(frame, *geo, points, &svg);
  Path(prior, frame, "stroke='#9ca3af' stroke-width='3' stroke-dasharray='8 5'", &svg);
  Path(current, frame, "stroke='#374151' stroke-width='2'", &svg);
  for (const GeometryRegion& r : report.geometry.regions) {
    const Eigen::Vector2d a = frame(r.box_min.head<2>()), b = frame(r.box_max.head<2>());
    svg << "<rect x='" << Fixed(std::min(a.x(), b.x()), 1) << "' y='" << Fixed(std::min(a.y(), b.y()), 1) << "' width='"
        << Fixed(std::abs(b.x() - a.x()) + 2, 1) << "' height='" << Fixed(std::abs(b.y() - a.y()) + 2, 1)
        << "' fill='#7c3aed22' stroke='#7c3aed' stroke-dasharray='4 2'/>\n";
  }
  Places(report, map, frame, &svg);
  MarkerLayout layout;
  for (const ChangeItem& item : items) {
    if (item.position) Marker(item, frame, &layout, &svg);
    if (!item.position && item.bearing) BearingMarker(item, frame, &layout, &svg);
  }
  ScaleBar(frame, &svg);
  if (geo) NorthArrow(frame, &svg);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace patrolmap::change
