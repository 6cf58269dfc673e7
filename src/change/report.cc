#include "patrolmap/change/report.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/core/files.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::change {
namespace {

using nlohmann::json;

json Vector(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
json Box(const cv::Rect& r) { return json::array({r.x, r.y, r.width, r.height}); }

double YawDegrees(const Eigen::Matrix3d& rotation) { return std::atan2(rotation(1, 0), rotation(0, 0)) * 180.0 / M_PI; }

json PlaceJson(const PlaceChange& place, const graph::TopoMap& map) {
  const AppearanceChange& a = place.appearance;
  json regions = json::array();
  for (const AppearanceRegion& r : a.regions) {
    regions.push_back({{"current_box", Box(r.current_box)},
                       {"prior_box", Box(r.prior_box)},
                       {"area_px", r.area_px},
                       {"score", r.score},
                       {"prior_features", r.prior_features},
                       {"unmatched_prior_features", r.unmatched_prior_features},
                       {"current_features", r.current_features},
                       {"unmatched_current_features", r.unmatched_current_features}});
  }
  return {{"prior_node", place.prior_node},
          {"current_node", place.current_node},
          {"prior_frame", map.node(place.prior_node).frame_index},
          {"current_frame", map.node(place.current_node).frame_index},
          {"registered", a.registered},
          {"matches", a.matches},
          {"inliers", a.inliers},
          {"gain", a.gain},
          {"offset", a.offset},
          {"compared_fraction", a.compared_fraction},
          {"regions", regions}};
}

json ObjectJson(const ObjectChange& o) {
  json object = {{"state", ToString(o.state)},
                 {"label", o.label},
                 {"confidence", o.confidence},
                 {"prior_id", o.prior_id},
                 {"current_id", o.current_id},
                 {"covering_views", o.covering_views},
                 {"expected_detections", o.expected_detections},
                 {"before", o.before ? Vector(*o.before) : json(nullptr)},
                 {"after", o.after ? Vector(*o.after) : json(nullptr)}};
  if (o.state == ObjectState::kMoved) {
    object["rotation_yaw_deg"] = YawDegrees(o.rotation);
    object["weighted_distance"] = o.weighted_distance;
  }
  return object;
}

json GeometryJson(const GeometryChange& g) {
  json regions = json::array();
  for (const GeometryRegion& r : g.regions) {
    regions.push_back({{"centroid", Vector(r.centroid)},
                       {"box_min", Vector(r.box_min)},
                       {"box_max", Vector(r.box_max)},
                       {"voxels", r.voxels},
                       {"appeared", r.appeared},
                       {"vanished", r.vanished},
                       {"score", r.score}});
  }
  return {{"voxel_size", g.voxel_size},
          {"compared_voxels", g.compared_voxels},
          {"evicted_voxels", {{"prior", g.evicted_prior}, {"current", g.evicted_current}}},
          {"depth_source", {{"prior", g.depth_prior}, {"current", g.depth_current}}},
          {"changed_voxels", g.changed_voxels.size()},
          {"regions", regions}};
}

const char* DepthWords(const std::string& source) {
  if (source == "images") return "depth images";
  if (source == "stereo") return "stereo matching";
  return "unrecorded";
}

// The key frame with regions outlined, twice its size.
cv::Mat Outlined(const cv::Mat& thumbnail, const std::vector<cv::Rect>& boxes) {
  cv::Mat colour;
  if (thumbnail.empty()) return colour;
  cv::cvtColor(thumbnail, colour, cv::COLOR_GRAY2BGR);
  cv::resize(colour, colour, cv::Size(), 2.0, 2.0, cv::INTER_NEAREST);
  for (const cv::Rect& box : boxes) {
    cv::rectangle(colour, cv::Rect(box.x * 2, box.y * 2, box.width * 2, box.height * 2), cv::Scalar(0, 0, 255), 2);
  }
  return colour;
}

const char* StateColour(ObjectState state) {
  switch (state) {
    case ObjectState::kPersistent: return "#1f77b4";
    case ObjectState::kNew: return "#2ca02c";
    case ObjectState::kRemoved: return "#d62728";
    case ObjectState::kMoved: return "#ff7f0e";
    case ObjectState::kUnobserved: return "#999999";
  }
  return "#000";
}

std::string Number(double value, int decimals = 2) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

// A plan (x right, y up) of the current flight's path, the objects and the geometry regions.
std::string PlanSvg(const ChangeReport& report, const graph::TopoMap& map) {
  std::vector<Eigen::Vector2d> points;
  const PatrolRecord* current = map.Patrol(report.current_flight);
  if (current != nullptr) {
    for (const CameraPoseSample& v : current->views) points.push_back(v.position.head<2>());
  }
  for (const ObjectChange& o : report.objects) {
    if (o.before) points.push_back(o.before->head<2>());
    if (o.after) points.push_back(o.after->head<2>());
  }
  for (const GeometryRegion& r : report.geometry.regions) points.push_back(r.centroid.head<2>());
  if (points.empty()) return "";
  Eigen::Vector2d lo = points[0], hi = points[0];
  for (const Eigen::Vector2d& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  lo -= Eigen::Vector2d(3, 3), hi += Eigen::Vector2d(3, 3);
  const double scale = 800.0 / std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const auto x = [&](double v) { return Number((v - lo.x()) * scale, 1); };
  const auto y = [&](double v) { return Number((hi.y() - v) * scale, 1); };
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << Number((hi.x() - lo.x()) * scale, 0) << "' height='"
      << Number((hi.y() - lo.y()) * scale, 0) << "' style='background:#fafafa;border:1px solid #ccc'>\n";
  if (current != nullptr && !current->views.empty()) {
    svg << "<polyline fill='none' stroke='#bbb' stroke-width='2' points='";
    for (const CameraPoseSample& v : current->views) svg << x(v.position.x()) << "," << y(v.position.y()) << " ";
    svg << "'/>\n";
  }
  for (const GeometryRegion& r : report.geometry.regions) {
    svg << "<rect x='" << x(r.box_min.x()) << "' y='" << y(r.box_max.y()) << "' width='"
        << Number((r.box_max.x() - r.box_min.x()) * scale + 2, 1) << "' height='"
        << Number((r.box_max.y() - r.box_min.y()) * scale + 2, 1)
        << "' fill='none' stroke='#9467bd' stroke-dasharray='4 2'><title>geometry: " << r.voxels
        << " voxels</title></rect>\n";
  }
  for (const ObjectChange& o : report.objects) {
    const Eigen::Vector3d& at = o.after ? *o.after : *o.before;
    if (o.state == ObjectState::kMoved) {
      svg << "<line x1='" << x(o.before->x()) << "' y1='" << y(o.before->y()) << "' x2='" << x(at.x()) << "' y2='"
          << y(at.y()) << "' stroke='" << StateColour(o.state) << "' stroke-width='2'/>\n";
    }
    svg << "<circle cx='" << x(at.x()) << "' cy='" << y(at.y()) << "' r='6' fill='" << StateColour(o.state)
        << "'><title>" << ToString(o.state) << " " << graph::EscapeXml(o.label) << " " << Number(o.confidence)
        << "</title></circle>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace

int ChangeReport::ChangedPlaces() const {
  return static_cast<int>(
      std::count_if(places.begin(), places.end(), [](const PlaceChange& p) { return !p.appearance.regions.empty(); }));
}

int ChangeReport::ObjectsIn(ObjectState state) const {
  return static_cast<int>(
      std::count_if(objects.begin(), objects.end(), [state](const ObjectChange& o) { return o.state == state; }));
}

std::string ToJson(const ChangeReport& report, const graph::TopoMap& map) {
  json places = json::array(), objects = json::array(), counts = json::object();
  for (const PlaceChange& place : report.places) places.push_back(PlaceJson(place, map));
  for (const ObjectChange& o : report.objects) objects.push_back(ObjectJson(o));
  for (ObjectState s : {ObjectState::kPersistent, ObjectState::kNew, ObjectState::kRemoved, ObjectState::kMoved,
                        ObjectState::kUnobserved}) {
    counts[ToString(s)] = report.ObjectsIn(s);
  }
  const json document = {
      {"format", "patrolmap.changes"},
      {"version", 1},
      {"prior_flight", report.prior_flight},
      {"current_flight", report.current_flight},
      {"summary",
       {{"places_compared", report.places.size()},
        {"places_changed", report.ChangedPlaces()},
        {"objects", report.objects_compared ? counts : json(nullptr)},
        {"geometry_regions", report.geometry_compared ? json(report.geometry.regions.size()) : json(nullptr)}}},
      {"timing_s",
       {{"appearance", report.seconds_appearance},
        {"objects", report.seconds_objects},
        {"geometry", report.seconds_geometry}}},
      {"places", places},
      {"objects", report.objects_compared ? objects : json(nullptr)},
      {"geometry", report.geometry_compared ? GeometryJson(report.geometry) : json(nullptr)}};
  return document.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string ToHtml(const ChangeReport& report, const graph::TopoMap& map) {
  std::ostringstream html;
  const std::string title =
      "Changes from " + graph::EscapeXml(report.prior_flight) + " to " + graph::EscapeXml(report.current_flight);
  html << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>" << title
       << "</title>\n<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
          "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}img{margin:4px;border:1px solid #888}"
          ".place{display:inline-block;margin:0 2em 2em 0;vertical-align:top}</style></head>\n<body>\n<h1>"
       << title << "</h1>\n<p>" << report.places.size() << " places seen by both patrols, " << report.ChangedPlaces()
       << " with appearance changes.";
  if (report.objects_compared) {
    html << " Objects: " << report.ObjectsIn(ObjectState::kNew) << " new, " << report.ObjectsIn(ObjectState::kRemoved)
         << " removed, " << report.ObjectsIn(ObjectState::kMoved) << " moved, "
         << report.ObjectsIn(ObjectState::kPersistent) << " persistent, " << report.ObjectsIn(ObjectState::kUnobserved)
         << " unobserved.";
  }
  if (report.geometry_compared) {
    html << " Geometry: " << report.geometry.regions.size() << " changed regions (depth: "
         << DepthWords(report.geometry.depth_prior) << " in the prior patrol, "
         << DepthWords(report.geometry.depth_current) << " in this one).";
  }
  if (report.geometry_compared && (report.geometry.evicted_prior > 0 || report.geometry.evicted_current > 0)) {
    html << " The evidence grids reached their memory budget (change.grid.memory_mb) and dropped their least "
            "recently observed voxels: "
         << report.geometry.evicted_prior << " of the prior patrol, " << report.geometry.evicted_current
         << " of this one; no geometry change can be found where they were.";
  }
  html << "</p>\n";
  if (report.objects_compared || report.geometry_compared) {
    html << "<h2>Plan</h2>\n<p>Grey: the current flight; dots: objects (blue persistent, green new, red removed, "
            "orange moved with its path, grey unobserved); dashed purple: changed geometry.</p>\n"
         << PlanSvg(report, map);
  }
  html << "<h2>Places with appearance changes</h2>\n";
  if (report.ChangedPlaces() == 0) {
    html << "<p>None of the " << report.places.size() << " places both patrols saw changed in appearance.</p>\n";
  }
  for (const PlaceChange& place : report.places) {
    if (place.appearance.regions.empty()) continue;
    std::vector<cv::Rect> prior_boxes, current_boxes;
    for (const AppearanceRegion& r : place.appearance.regions) {
      prior_boxes.push_back(r.prior_box);
      current_boxes.push_back(r.current_box);
    }
    html << "<div class='place'><p>node " << place.prior_node << " (frame " << map.node(place.prior_node).frame_index
         << ") &rarr; node " << place.current_node << " (frame " << map.node(place.current_node).frame_index << "), "
         << place.appearance.regions.size() << " region(s), best score " << Number(place.appearance.regions[0].score)
         << "</p><img alt='prior' src='"
         << graph::PngDataUri(Outlined(map.node(place.prior_node).thumbnail, prior_boxes))
         << "'><img alt='current' src='"
         << graph::PngDataUri(Outlined(map.node(place.current_node).thumbnail, current_boxes)) << "'></div>\n";
  }
  if (report.objects_compared) {
    html << "<h2>Objects</h2>\n<table><tr><th>state</th><th>label</th><th>confidence</th><th>before [m]</th>"
            "<th>after [m]</th><th>covering views</th><th>expected detections</th></tr>\n";
    const auto position = [](const std::optional<Eigen::Vector3d>& p) {
      return p ? Number(p->x()) + ", " + Number(p->y()) + ", " + Number(p->z()) : std::string("&ndash;");
    };
    for (const ObjectChange& o : report.objects) {
      html << "<tr><td style='color:" << StateColour(o.state) << "'>" << ToString(o.state) << "</td><td>"
           << graph::EscapeXml(o.label) << "</td><td>" << Number(o.confidence) << "</td><td>" << position(o.before)
           << "</td><td>" << position(o.after) << "</td><td>" << o.covering_views << "</td><td>"
           << Number(o.expected_detections) << "</td></tr>\n";
    }
    html << "</table>\n";
  }
  html << "</body></html>\n";
  return html.str();
}

Status WriteChangeReport(const ChangeReport& report, const graph::TopoMap& map, const std::string& folder) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/changes.json", ToJson(report, map)));
  return WriteFileAtomically(folder + "/changes.html", ToHtml(report, map));
}

}  // namespace patrolmap::change
