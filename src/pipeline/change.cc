#include "patrolmap/pipeline/change.h"

#include <algorithm>
#include <chrono>

#include <spdlog/spdlog.h>

#include "patrolmap/change/geometry_objects.h"

namespace patrolmap::pipeline {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Status CompareFlights(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                      const change::ChangeOptions& options, change::ChangeReport* report) {
  const std::vector<std::string> flights = map.Flights();
  for (const std::string& flight : {prior, current}) {
    if (std::find(flights.begin(), flights.end(), flight) == flights.end()) {
      return Status::InvalidArgument("flight '" + flight + "' is not in the map");
    }
  }
  *report = change::ChangeReport();
  report->prior_flight = prior;
  report->current_flight = current;
  const PatrolRecord* prior_record = map.Patrol(prior);
  const PatrolRecord* current_record = map.Patrol(current);

  auto start = std::chrono::steady_clock::now();
  const bool along_route = options.route.enabled && prior_record != nullptr && current_record != nullptr &&
                           !prior_record->route.empty() && !current_record->route.empty();
  std::vector<change::RouteAnchor> anchors;
  for (const graph::TopoMap::Edge& edge : map.Edges()) {
    if (edge.data.kind != graph::EdgeKind::kLoopClosure) continue;
    int a = edge.a, b = edge.b;
    if (map.node(a).flight == current) std::swap(a, b);
    if (map.node(a).flight != prior || map.node(b).flight != current) continue;
    const auto view = [&map](int node, const PatrolRecord* record) {
      const graph::NodeData& n = map.node(node);
      change::KeyFrameView v;
      v.image = n.thumbnail;
      v.points = n.points;
      v.descriptors = n.descriptors;
      if (record != nullptr && record->feature_image_width > 0 && !n.thumbnail.empty()) {
        v.feature_scale = static_cast<double>(record->feature_image_width) / n.thumbnail.cols;
      }
      return v;
    };
    change::PlaceChange place;
    place.prior_node = a, place.current_node = b;
    anchors.push_back({map.node(a).timestamp_ns, map.node(b).timestamp_ns});
    if (!along_route) {
      place.appearance =
          change::DetectAppearanceChange(view(a, prior_record), view(b, current_record), options.appearance);
    }
    report->places.push_back(std::move(place));
  }
  if (along_route) {
    spdlog::info("{}: comparing its {} route frames with the {} of {} (appearance along the route)", current,
                 current_record->route.size(), prior_record->route.size(), prior);
    report->route = change::CompareRoutes(prior_record->route, current_record->route, anchors, options.route,
                                          options.appearance, change::RouteCamerasOf(*prior_record, *current_record));
  }
  report->seconds_appearance = SecondsSince(start);
  if (prior_record == nullptr || current_record == nullptr) return Status::Ok();
  report->pose_prior = prior_record->pose_source;
  report->pose_current = current_record->pose_source;

  start = std::chrono::steady_clock::now();
  if (!prior_record->grid.voxels.empty() && !current_record->grid.voxels.empty()) {
    spdlog::info("{}: comparing its evidence grid ({} voxels) with {}'s ({}; geometry and objects)", current,
                 current_record->grid.voxels.size(), prior, prior_record->grid.voxels.size());
  }
  report->geometry_compared = change::DiffGrids(
      prior_record->grid, current_record->grid,
      change::ForPoseSources(options.geometry, prior_record->pose_source, current_record->pose_source),
      &report->geometry);
  report->geometry.depth_prior = prior_record->depth_source;
  report->geometry.depth_current = current_record->depth_source;
  if (report->geometry.poses_disagree) {
    // Objects are placed by the same poses: their comparison would be as wrong.
    spdlog::warn(
        "{} and {}: their surfaces differ in {:.0f} % of the voxels both observed ({} of {}; more than "
        "change.geometry.max_differing_share, {:.0f} %): the two flights' camera poses disagree (GPS without "
        "RTK, or another world frame), so no geometry or object change is reported",
        prior, current, 100.0 * report->geometry.DifferingShare(), report->geometry.differing_voxels,
        report->geometry.surface_voxels, 100.0 * options.geometry.max_differing_share);
    report->seconds_geometry = SecondsSince(start);
    return Status::Ok();
  }
  if (report->geometry_compared && options.geometry_objects.enabled) {
    // Objects no detector named: clusters of changed space (paper 003); detected objects take precedence.
    report->objects = change::GeometryObjects(
        report->geometry, change::LookupIn(prior_record->grid), change::LookupIn(current_record->grid),
        prior_record->objects, current_record->objects,
        change::ForPoseSources(options.geometry_objects, prior_record->pose_source, current_record->pose_source));
    report->objects_compared = true;
  }
  report->seconds_geometry = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  if (prior_record->has_objects && current_record->has_objects) {
    std::vector<change::ObjectChange> detected = change::DiffObjects(*prior_record, *current_record, options.objects);
    report->objects.insert(report->objects.begin(), detected.begin(), detected.end());
    report->objects_compared = true;
  }
  report->seconds_objects = SecondsSince(start);
  return Status::Ok();
}

Status ReportLastFlight(const graph::TopoMap& prior, const graph::TopoMap& map, const change::ChangeOptions& options,
                        const std::string& folder, change::ChangeReport* report, bool* compared) {
  const std::vector<std::string> before = prior.Flights(), after = map.Flights();
  if (compared != nullptr) *compared = false;
  if (before.empty() || after.size() <= before.size()) return Status::Ok();
  PATROLMAP_RETURN_IF_ERROR(CompareFlights(map, before.back(), after.back(), options, report));
  PATROLMAP_RETURN_IF_ERROR(change::WriteChangeReport(*report, map, folder));
  if (compared != nullptr) *compared = true;
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
