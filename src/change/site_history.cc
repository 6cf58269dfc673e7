#include "patrolmap/change/site_history.h"

#include <algorithm>
#include <map>
#include <set>

#include "patrolmap/change/object_diff.h"

namespace patrolmap::change {
namespace {

// A site object as the patrols so far saw it.
struct Tracked {
  SiteObjectHistory history;
  bool seen_last = false;                     // the last patrol that covered its place saw it
  MapObject last;                             // as last seen ...
  const PatrolRecord* last_record = nullptr;  // ... by this patrol
};

Status FlightIndex(const std::vector<std::string>& flights, const std::string& flight, int fallback, int* index) {
  if (flight.empty()) return *index = fallback, Status::Ok();
  const auto found = std::find(flights.begin(), flights.end(), flight);
  if (found == flights.end()) return Status::InvalidArgument("flight '" + flight + "' is not in the map");
  *index = static_cast<int>(found - flights.begin());
  return Status::Ok();
}

void Sighted(const MapObject& o, const PatrolRecord& record, int patrol, const ObjectDiffOptions& options, Tracked* t) {
  SiteObjectHistory& h = t->history;
  const Eigen::Vector3d& p = o.centroid;
  if (h.sightings == 0) {
    h.id = o.site_id;
    h.events.push_back({record.flight, patrol, "first seen", std::nullopt, p});
  } else if (!t->seen_last) {
    h.events.push_back({record.flight, patrol, "seen again", h.at, p});
  } else if ((p - *h.at).norm() > options.match_distance_m) {
    h.events.push_back({record.flight, patrol, "moved", h.at, p});
  }
  h.label = o.label;
  h.at = p;
  ++h.sightings;
  t->seen_last = true;
  t->last = o;
  t->last_record = &record;
}

// Whether `record` (which did not detect it) would have detected `t`'s object where it was last seen.
bool Missed(const Tracked& t, const PatrolRecord& record, const ObjectDiffOptions& options) {
  const int views = CoveringViews(t.last, record, options);
  if (views == 0) return false;
  const int own_views = CoveringViews(t.last, *t.last_record, options);
  return ExpectedDetections(t.last, own_views, views) >= options.min_expected_detections;
}

bool Passes(const SiteObjectHistory& h, const SiteHistoryFilter& filter) {
  if (filter.object >= 0 && h.id != filter.object) return false;
  return !filter.near || (h.at && (h.at->head<2>() - *filter.near).norm() <= filter.radius_m);
}

}  // namespace

Status SiteHistory(const graph::TopoMap& map, const ObjectDiffOptions& options, const SiteHistoryFilter& filter,
                   std::vector<SiteObjectHistory>* history) {
  const std::vector<std::string> flights = map.Flights();
  int first = 0, last = static_cast<int>(flights.size()) - 1;
  PATROLMAP_RETURN_IF_ERROR(FlightIndex(flights, filter.from, first, &first));
  PATROLMAP_RETURN_IF_ERROR(FlightIndex(flights, filter.to, last, &last));
  std::map<int, Tracked> tracked;
  for (int i = first; i <= last; ++i) {
    const PatrolRecord* record = map.Patrol(flights[i]);
    if (record == nullptr || !record->has_objects) continue;
    std::set<int> here;
    for (const MapObject& o : record->objects) {
      if (o.site_id < 0 || !o.confirmed) continue;
      here.insert(o.site_id);
      Sighted(o, *record, i + 1, options, &tracked[o.site_id]);
    }
    for (auto& [id, t] : tracked) {
      if (here.count(id) != 0 || !t.seen_last || !Missed(t, *record, options)) continue;
      t.history.events.push_back({record->flight, i + 1, "not seen", t.history.at, std::nullopt});
      t.seen_last = false;
    }
  }
  history->clear();
  for (const auto& [id, t] : tracked) {
    if (Passes(t.history, filter)) history->push_back(t.history);
  }
  return Status::Ok();
}

std::vector<SiteObjectHistory> SiteHistoriesOf(const graph::TopoMap& map, const ObjectDiffOptions& options,
                                               const std::vector<int>& site_ids) {
  std::vector<SiteObjectHistory> all, wanted;
  if (!SiteHistory(map, options, {}, &all).ok()) return wanted;  // the whole map: no flight to miss
  for (const SiteObjectHistory& h : all) {
    if (std::find(site_ids.begin(), site_ids.end(), h.id) != site_ids.end()) wanted.push_back(h);
  }
  return wanted;
}

}  // namespace patrolmap::change
