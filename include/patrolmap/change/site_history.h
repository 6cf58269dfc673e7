// The history of a site's objects over the patrols a map holds (site ids: change/site_objects.h). Per site object,
// in the order flown: where each patrol that detected it saw it, and what happened between them: first seen, moved
// (its position further from the last one than ObjectDiffOptions::match_distance_m), not seen (a later patrol with
// detections covered its last place, CoveringViews, and did not see it), seen again. A patrol that did not cover
// its place says nothing of it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/change/options.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

struct SiteEvent {
  std::string flight;                       // the patrol it was found in
  int patrol = 0;                           // that patrol's place among the map's flights, from 1
  std::string what;                         // "first seen", "moved", "not seen", "seen again"
  std::optional<Eigen::Vector3d> from, to;  // moved: from, to; first seen, seen again: to; not seen: from [m]
};

struct SiteObjectHistory {
  int id = 0;
  std::string label;                  // the label it was last seen with
  std::optional<Eigen::Vector3d> at;  // where it was last seen [m]
  int sightings = 0;                  // patrols that detected it
  std::vector<SiteEvent> events;
};

struct SiteHistoryFilter {
  int object = -1;                      // one site object (-1: all)
  std::optional<Eigen::Vector2d> near;  // objects last seen within radius_m of this place (east, north) [m]
  double radius_m = 10.0;
  std::string from, to;  // the patrols from and to these flights (empty: the first, the last)
};

// The site objects of `map` that pass `filter`, by id, with the events in the patrols it keeps; InvalidArgument
// naming a flight the map does not hold.
Status SiteHistory(const graph::TopoMap& map, const ObjectDiffOptions& options, const SiteHistoryFilter& filter,
                   std::vector<SiteObjectHistory>* history);

// The histories (all of `map`'s patrols) of the site objects `site_ids` name, by id; ids below 0 are skipped.
std::vector<SiteObjectHistory> SiteHistoriesOf(const graph::TopoMap& map, const ObjectDiffOptions& options,
                                               const std::vector<int>& site_ids);

}  // namespace patrolmap::change
