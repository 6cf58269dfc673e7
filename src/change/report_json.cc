// changes.json: format "patrolmap.changes", version 2 (docs/changes.schema.json).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "patrolmap/change/report.h"

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
  return {{"id", AppearanceChangeId(place.prior_node, place.current_node)},
          {"prior_node", place.prior_node},
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

// The route comparison: what share of the route was compared, and per change its views (the route frames of
// each agreeing pair and the region's boxes in them). `ids`: the changes' ids in the report, in order.
json RouteJson(const ChangeReport& report, const graph::TopoMap& map, const std::vector<std::string>& ids) {
  if (!report.route.compared) return nullptr;
  const std::vector<RouteFrame>& prior = map.Patrol(report.prior_flight)->route;
  const std::vector<RouteFrame>& current = map.Patrol(report.current_flight)->route;
  json changes = json::array();
  for (std::size_t i = 0; i < report.route.changes.size(); ++i) {
    const RouteChange& change = report.route.changes[i];
    json views = json::array();
    for (const RouteChange::View& v : change.views) {
      const RoutePair& pair = report.route.pairs[v.pair];
      const AppearanceRegion& r = pair.appearance.regions[v.region];
      views.push_back({{"prior_frame", prior[pair.prior].frame_index},
                       {"current_frame", current[pair.current].frame_index},
                       {"prior_box", Box(r.prior_box)},
                       {"current_box", Box(r.current_box)},
                       {"score", r.score},
                       {"marked_share", r.marked_share}});
    }
    changes.push_back({{"id", i < ids.size() ? ids[i] : std::string()},
                       {"confidence", change.confidence},
                       {"score", change.score},
                       {"marked_share", change.marked_share},
                       {"located", ToString(change.location.by)},
                       {"position", change.location.HasPoint() ? Vector(change.location.point) : json(nullptr)},
                       {"views", views}});
  }
  return {{"frames", report.route.current_frames},
          {"compared_pairs", report.route.pairs.size()},
          {"compared_share", report.route.ComparedShare()},
          {"frames_with_depth",
           {{"prior", report.route.prior_depth_frames}, {"current", report.route.current_depth_frames}}},
          {"changes", changes}};
}

json ObjectJson(const ObjectChange& o) {
  json object = {{"id", ObjectChangeId(o)},
                 {"state", ToString(o.state)},
                 {"label", o.label},
                 {"source", o.class_agnostic ? "geometry" : "detections"},
                 {"site_object", o.site_id >= 0 ? json(o.site_id) : json(nullptr)},
                 {"confidence", o.confidence},
                 {"prior_id", o.prior_id},
                 {"current_id", o.current_id},
                 {"covering_views", o.covering_views},
                 {"expected_detections", o.expected_detections},
                 {"before", o.before ? Vector(*o.before) : json(nullptr)},
                 {"after", o.after ? Vector(*o.after) : json(nullptr)}};
  const auto box = [](const Eigen::AlignedBox3d& b) {
    return b.isEmpty() ? json(nullptr) : json({{"min", Vector(b.min())}, {"max", Vector(b.max())}});
  };
  if (o.class_agnostic) {
    object["box_before"] = box(o.box_before);
    object["box_after"] = box(o.box_after);
  }
  if (o.state == ObjectState::kMoved) {
    object["rotation_yaw_deg"] = YawDegrees(o.rotation);
    object["weighted_distance"] = o.weighted_distance;
  }
  return object;
}

// Region ids as the changes list has them (made unique there), in region order.
json GeometryJson(const GeometryChange& g, const std::vector<ChangeItem>& items) {
  const std::vector<std::string> ids = IdsOf(items, "geometry", g.regions.size());
  json regions = json::array();
  for (std::size_t k = 0; k < g.regions.size(); ++k) {
    const GeometryRegion& r = g.regions[k];
    regions.push_back({{"id", ids[k].empty() ? GeometryChangeId(r.centroid) : ids[k]},
                       {"centroid", Vector(r.centroid)},
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
          {"surface_voxels", g.surface_voxels},
          {"differing_voxels", g.differing_voxels},
          {"poses_disagree", g.poses_disagree},
          {"regions", regions}};
}

json ViewJson(const ChangeItem& item, bool before, const std::string& images) {
  const ChangeView& view = before ? item.before : item.after;
  if (view.frame_index < 0)
    return {{"flight", view.flight}, {"time_s", nullptr}, {"frame", nullptr}, {"image", nullptr}};
  const json image =
      view.image.empty() || images.empty() ? json(nullptr) : json(images + "/" + ViewFileName(item, before));
  return {{"flight", view.flight},
          {"time_s", NsToSeconds(view.timestamp_ns)},
          {"frame", view.frame_index},
          {"image", image}};
}

// The other channels' findings fused into the entry.
json EvidenceJson(const ChangeItem& item) {
  json evidence = json::array();
  for (const ChangeEvidence& e : item.evidence) {
    evidence.push_back({{"channel", e.channel},
                        {"id", e.id},
                        {"kind", e.kind},
                        {"state", e.state},
                        {"label", e.label},
                        {"confidence", e.confidence},
                        {"position", e.position ? Vector(*e.position) : json(nullptr)},
                        {"located", e.located.empty() ? json(nullptr) : json(e.located)}});
  }
  return evidence;
}

json ChangeJson(const ChangeItem& item, const std::optional<GeoReference>& geo, const std::string& images) {
  json change = {{"id", item.id},
                 {"number", item.number},
                 {"kind", item.kind},
                 {"state", item.state},
                 {"label", item.label},
                 {"confidence", item.confidence},
                 {"position", item.position ? Vector(*item.position) : json(nullptr)},
                 {"from", item.from ? Vector(*item.from) : json(nullptr)},
                 {"site_object", item.site_object >= 0 ? json(item.site_object) : json(nullptr)},
                 {"located", item.located.empty() ? json(nullptr) : json(item.located)},
                 {"bearing", item.bearing ? json({{"origin", Vector(item.bearing->origin)},
                                                  {"direction", Vector(item.bearing->direction)},
                                                  {"range_m", item.bearing_range_m}})
                                          : json(nullptr)},
                 {"latitude", nullptr},
                 {"longitude", nullptr},
                 {"channels", item.channels},
                 {"evidence", EvidenceJson(item)},
                 {"compared_in_3d", item.compared_in_3d ? json(*item.compared_in_3d) : json(nullptr)},
                 {"before", ViewJson(item, true, images)},
                 {"after", ViewJson(item, false, images)}};
  if (geo && item.position) {
    const Eigen::Vector2d lat_lon = geo->LatitudeLongitude(*item.position);
    change["latitude"] = lat_lon.x();
    change["longitude"] = lat_lon.y();
  }
  return change;
}

json GridSourcesJson(const std::vector<GridSource>& sources) {
  json list = json::array();
  for (const GridSource& s : sources)
    list.push_back({{"flight", s.flight}, {"voxels", s.voxels}, {"flown_ns", s.flown_ns}});
  return list;
}

}  // namespace

std::string ToJson(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                   const std::optional<GeoReference>& geo, const std::string& images) {
  json places = json::array(), objects = json::array(), counts = json::object(), changes = json::array();
  for (const PlaceChange& place : report.places) places.push_back(PlaceJson(place, map));
  for (const ObjectChange& o : report.objects) objects.push_back(ObjectJson(o));
  for (ObjectState s : {ObjectState::kPersistent, ObjectState::kNew, ObjectState::kRemoved, ObjectState::kMoved,
                        ObjectState::kUnobserved}) {
    counts[ToString(s)] = report.ObjectsIn(s);
  }
  for (const ChangeItem& item : items) changes.push_back(ChangeJson(item, geo, images));
  const std::vector<std::string> route_ids = IdsOf(items, "route", report.route.changes.size());
  json geo_json = nullptr;
  if (geo) {
    geo_json = {{"origin_latitude", geo->origin_latitude},
                {"origin_longitude", geo->origin_longitude},
                {"fixes", geo->fixes},
                {"rms_m", geo->rms_m}};
  }
  const json document = {
      {"format", "patrolmap.changes"},
      {"version", 2},
      {"prior_flight", report.prior_flight},
      {"current_flight", report.current_flight},
      {"pose_source", {{"prior", report.pose_prior}, {"current", report.pose_current}}},
      {"geometry_reference", GridSourcesJson(report.grid_sources)},
      {"summary",
       {{"changes", items.size()},
        {"places_compared", report.places.size()},
        {"places_changed", report.ChangedPlaces()},
        {"objects", report.objects_compared ? counts : json(nullptr)},
        {"geometry_regions", report.geometry_compared ? json(report.geometry.regions.size()) : json(nullptr)}}},
      {"timing_s",
       {{"appearance", report.seconds_appearance},
        {"objects", report.seconds_objects},
        {"geometry", report.seconds_geometry}}},
      {"geo_reference", geo_json},
      {"changes", changes},
      {"places", places},
      {"route", RouteJson(report, map, route_ids)},
      {"objects", report.objects_compared ? objects : json(nullptr)},
      {"geometry", report.geometry_compared ? GeometryJson(report.geometry, items) : json(nullptr)}};
  return document.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {

// A point of changes.json: null, or three finite numbers.
std::optional<Eigen::Vector3d> PointOf(const json& p, const char* key) {
  if (p.is_null()) return std::nullopt;
  if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
    throw std::invalid_argument(std::string("'") + key + "' is not null or three numbers");
  return Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
}

// Reads item i of list `name` with `read`, naming the item in what it throws.
template <typename Read>
void ReadEach(const json& list, const char* name, Read read) {
  for (std::size_t i = 0; i < list.size(); ++i) {
    try {
      read(list[i]);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string(name) + "[" + std::to_string(i) + "]: " + e.what());
    }
  }
}

void ReadObjects(const json& objects, ChangesFile* file) {
  ReadEach(objects, "objects", [&](const json& o) {
    ChangesFile::Object object;
    object.id = o.value("id", "");
    object.state = o.at("state").get<std::string>();
    object.label = o.at("label").get<std::string>();
    object.from_geometry = o.value("source", "detections") == "geometry";
    object.before = PointOf(o.at("before"), "before");
    object.after = PointOf(o.at("after"), "after");
    file->objects.push_back(object);
  });
}

void ReadEntries(const json& changes, ChangesFile* file) {
  ReadEach(changes, "changes", [&](const json& c) {
    file->entries.push_back(
        {c.at("id").get<std::string>(), PointOf(c.at("position"), "position"), PointOf(c.at("from"), "from")});
  });
}

}  // namespace

Status ReadChangesJson(const std::string& path, ChangesFile* file) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot be read");
  json document;
  try {
    document = json::parse(in);
  } catch (const json::exception& e) {
    return Status::DataLoss(path + ": not JSON: " + e.what());
  }
  if (!document.is_object() || document.value("format", "") != "patrolmap.changes")
    return Status::DataLoss(path + ": not a patrolmap change report (\"format\": \"patrolmap.changes\")");
  *file = ChangesFile();
  try {
    file->prior_flight = document.at("prior_flight").get<std::string>();
    file->current_flight = document.at("current_flight").get<std::string>();
    const json& summary = document.at("summary");
    file->places_compared = summary.value("places_compared", 0);
    file->places_changed = summary.value("places_changed", 0);
    const json& objects = document.value("objects", json());
    file->objects_compared = objects.is_array();
    if (file->objects_compared) ReadObjects(objects, file);
    const json& changes = document.value("changes", json::array());
    if (!changes.is_array()) throw std::invalid_argument("'changes' is not an array");
    ReadEntries(changes, file);
  } catch (const std::exception& e) {
    return Status::DataLoss(path + ": malformed change report: " + e.what());
  }
  return Status::Ok();
}

}  // namespace patrolmap::change
