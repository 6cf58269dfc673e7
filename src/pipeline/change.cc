#include "patrolmap/pipeline/change.h"

#include <algorithm>

#include <spdlog/spdlog.h>

#include "patrolmap/change/change_detector.h"
#include "patrolmap/change/site_objects.h"
#include "patrolmap/change/site_state.h"

namespace patrolmap::pipeline {
namespace {

// A node's camera pose is the patrol's view nearest its time, within this [s].
constexpr double kNodePoseToleranceS = 1.0;

// The loop closures between nodes of `prior` and of `current`, each with its two key frames.
std::vector<change::PlacePair> PlacesOf(const graph::TopoMap& map, const PatrolRecord& prior,
                                        const PatrolRecord& current) {
  const auto view = [&map](int node, const PatrolRecord& record) {
    const KeyFrameNode& n = map.node(node);
    return change::KeyFrameOf(n.thumbnail, n.points, n.descriptors, record.feature_image_width);
  };
  std::vector<change::PlacePair> places;
  for (const graph::TopoMap::Edge& edge : map.Edges()) {
    if (edge.data.kind != graph::EdgeKind::kLoopClosure) continue;
    int a = edge.a, b = edge.b;
    if (map.node(a).flight == current.flight) std::swap(a, b);
    if (map.node(a).flight != prior.flight || map.node(b).flight != current.flight) continue;
    places.push_back({a, b, map.node(a).timestamp_ns, map.node(b).timestamp_ns, view(a, prior), view(b, current),
                      ViewAt(current, map.node(b).timestamp_ns, SecondsToNs(kNodePoseToleranceS))});
  }
  return places;
}

// `flight`'s patrol record, or `places_only` named after it when the map has none.
const PatrolRecord& RecordOf(const graph::TopoMap& map, const std::string& flight, PatrolRecord* places_only) {
  const PatrolRecord* record = map.Patrol(flight);
  if (record != nullptr) return *record;
  places_only->flight = flight;
  return *places_only;
}

// What the comparison is about to do, for the log: its two long phases.
void LogPhases(const PatrolRecord& prior, const PatrolRecord& current, const change::ChangeOptions& options) {
  if (options.route.enabled && !prior.route.empty() && !current.route.empty()) {
    spdlog::info("{}: comparing its {} route frames with the {} of {} (appearance along the route)", current.flight,
                 current.route.size(), prior.route.size(), prior.flight);
  }
  if (!prior.grid.voxels.empty() && !current.grid.voxels.empty()) {
    spdlog::info("{}: comparing its evidence grid ({} voxels) with {}'s ({}; geometry and objects)", current.flight,
                 current.grid.voxels.size(), prior.flight, prior.grid.voxels.size());
  }
}

// Which earlier patrols completed the reference grid (the regions the prior flight did not observe).
void LogSources(const std::vector<change::GridSource>& sources, const std::string& current) {
  for (std::size_t i = 1; i < sources.size(); ++i) {
    spdlog::info("{}: {} voxels only {} observed (the latest state there) are compared too", current, sources[i].voxels,
                 sources[i].flight);
  }
}

std::vector<int> SiteIdsOf(const change::ChangeReport& report) {
  std::vector<int> ids;
  for (const change::ObjectChange& o : report.objects) ids.push_back(o.site_id);
  return ids;
}

// The site objects of `map`'s flight `current` carried from the flights before it (`before`, numbered first where
// a map written before site ids left them without), by `report`, the comparison with the last of them; then the
// report's object changes named by them.
void CarrySiteObjects(const std::vector<std::string>& before, const std::string& current, change::ChangeReport* report,
                      graph::TopoMap* map) {
  int last = change::LargestSiteId(*map);
  for (const std::string& flight : before) {
    if (PatrolRecord* record = map->MutablePatrol(flight)) change::NumberSiteObjects(record, &last);
  }
  const PatrolRecord* prior = map->Patrol(before.back());
  PatrolRecord* now = map->MutablePatrol(current);
  if (prior == nullptr || now == nullptr) return;
  change::CarrySiteObjects(*prior, *report, now, &last);
  change::NameSiteObjects(*prior, *now, report);
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
  // A flight without a patrol record (a map of key frames only) is compared at its places.
  PatrolRecord prior_places, current_places;
  const PatrolRecord& prior_record = RecordOf(map, prior, &prior_places);
  const PatrolRecord& current_record = RecordOf(map, current, &current_places);
  for (const PatrolRecord* record : {&prior_record, &current_record}) {
    if (record->archived) {
      spdlog::warn(
          "{}: archived by later patrols (map.whole_patrols): its evidence grid keeps only the voxels no later patrol "
          "observed and its route frames are thinned out, so this comparison sees less of it than when it was flown",
          record->flight);
    }
  }
  std::vector<change::GridSource> sources;
  const PatrolRecord reference = change::LatestState(map, prior_record, &sources);
  LogPhases(reference, current_record, options);
  LogSources(sources, current);
  const change::ChangeDetector detector(reference, options);
  detector.Compare(current_record, PlacesOf(map, prior_record, current_record), report);
  report->grid_sources = std::move(sources);
  change::NameSiteObjects(prior_record, current_record, report);
  if (report->geometry.poses_disagree) {
    spdlog::warn(
        "{} and {}: their surfaces differ in {:.0f} % of the voxels both observed ({} of {}; more than "
        "change.geometry.max_differing_share, {:.0f} %): the two flights' camera poses disagree (GPS without "
        "RTK, or another world frame), so no geometry or object change is reported",
        prior, current, 100.0 * report->geometry.DifferingShare(), report->geometry.differing_voxels,
        report->geometry.surface_voxels, 100.0 * options.geometry.max_differing_share);
  }
  return Status::Ok();
}

void AddSiteHistories(const graph::TopoMap& map, const change::ObjectDiffOptions& options,
                      change::ChangeReport* report) {
  report->site_objects = change::SiteHistoriesOf(map, options, SiteIdsOf(*report));
}

Status ReportLastFlight(const graph::TopoMap& prior, graph::TopoMap* map, const change::ChangeOptions& options,
                        const std::string& folder, change::ChangeReport* report, bool* compared,
                        std::vector<change::ChangeItem>* entries) {
  const std::vector<std::string> before = prior.Flights(), after = map->Flights();
  if (compared != nullptr) *compared = false;
  if (before.empty() || after.size() <= before.size()) return Status::Ok();
  PATROLMAP_RETURN_IF_ERROR(CompareFlights(*map, before.back(), after.back(), options, report));
  CarrySiteObjects(before, after.back(), report, map);
  AddSiteHistories(*map, options.objects, report);
  PATROLMAP_RETURN_IF_ERROR(change::WriteChangeReport(*report, *map, folder, entries));
  if (compared != nullptr) *compared = true;
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
