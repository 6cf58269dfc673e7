// changes.geojson (RFC 7946): every change as a point at [longitude, latitude] with its properties (an appearance
// change known only by its bearing as the ray from the camera it lies on), moved objects' paths, and each flight's
// GPS track (the fixes of its kept frames) as a line.
#include <nlohmann/json.hpp>

#include "patrolmap/change/report.h"

namespace patrolmap::change {
namespace {

using nlohmann::json;

json LonLat(const GeoReference& geo, const Eigen::Vector3d& world) {
  const Eigen::Vector2d lat_lon = geo.LatitudeLongitude(world);
  return json::array({lat_lon.y(), lat_lon.x()});
}

json ViewProperties(const ChangeView& view) {
  if (view.frame_index < 0) return nullptr;
  return {{"flight", view.flight}, {"time_s", NsToSeconds(view.timestamp_ns)}, {"frame", view.frame_index}};
}

// A change at its point, or, placed by a bearing only, as the ray from the camera it lies on.
json ChangeFeature(const ChangeItem& item, const GeoReference& geo) {
  const json geometry =
      item.position
          ? json({{"type", "Point"}, {"coordinates", LonLat(geo, *item.position)}})
          : json({{"type", "LineString"},
                  {"coordinates", json::array({LonLat(geo, item.bearing->origin), LonLat(geo, BearingEnd(item))})}});
  return {{"type", "Feature"},
          {"id", item.id},
          {"geometry", geometry},
          {"properties",
           {{"id", item.id},
            {"number", item.number},
            {"kind", item.kind},
            {"state", item.state},
            {"label", item.label},
            {"confidence", item.confidence},
            {"located", item.located.empty() ? json(nullptr) : json(item.located)},
            {"height_m", item.position ? json(item.position->z()) : json(nullptr)},
            {"before", ViewProperties(item.before)},
            {"after", ViewProperties(item.after)}}}};
}

// The flight's GPS track (its kept frames' fixes) and its camera path through `geo`.
void FlightFeatures(const graph::TopoMap& map, const std::string& flight, const GeoReference& geo, json* features) {
  const PatrolRecord* record = map.Patrol(flight);
  if (record == nullptr) return;
  json track = json::array(), path = json::array();
  for (const RouteFrame& frame : record->route) {
    if (frame.gps) track.push_back({frame.gps->y(), frame.gps->x()});
  }
  for (const CameraPoseSample& view : record->views) path.push_back(LonLat(geo, view.position));
  for (auto& [line, kind] : {std::pair{track, "gps_track"}, std::pair{path, "camera_path"}}) {
    if (line.size() < 2) continue;
    features->push_back({{"type", "Feature"},
                         {"geometry", {{"type", "LineString"}, {"coordinates", line}}},
                         {"properties", {{"flight", flight}, {"kind", kind}}}});
  }
}

}  // namespace

std::string ToGeoJson(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                      const GeoReference& geo) {
  json features = json::array();
  for (const std::string& flight : {report.prior_flight, report.current_flight}) {
    FlightFeatures(map, flight, geo, &features);
  }
  for (const ChangeItem& item : items) {
    if (!item.position && !item.bearing) continue;
    features.push_back(ChangeFeature(item, geo));
    if (!item.from) continue;
    features.push_back({{"type", "Feature"},
                        {"geometry",
                         {{"type", "LineString"},
                          {"coordinates", json::array({LonLat(geo, *item.from), LonLat(geo, *item.position)})}}},
                        {"properties", {{"id", item.id}, {"kind", "move"}}}});
  }
  return json({{"type", "FeatureCollection"}, {"features", features}})
             .dump(1, ' ', false, json::error_handler_t::replace) +
         "\n";
}

}  // namespace patrolmap::change
