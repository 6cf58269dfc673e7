// The change report between two patrols of a map: per place the appearance
// change, per object its state, and the changed geometry. Written as JSON
// (format "patrolmap.changes", version 1; docs/changes.schema.json) and as a
// self-contained HTML page: per changed place the prior and current key
// frames side by side with the changed regions outlined, a plan of the
// objects and geometry regions, and a table of the objects.
#pragma once

#include <string>
#include <vector>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

struct PlaceChange {
  int prior_node = -1, current_node = -1;  // map nodes (a loop closure between the two flights)
  AppearanceChange appearance;
};

struct ChangeReport {
  std::string prior_flight, current_flight;
  std::vector<PlaceChange> places;  // every place both patrols saw
  bool objects_compared = false;    // both patrols had detections and poses
  std::vector<ObjectChange> objects;
  bool geometry_compared = false;  // both patrols had depth and poses
  GeometryChange geometry;
  double seconds_appearance = 0.0, seconds_objects = 0.0, seconds_geometry = 0.0;

  int ChangedPlaces() const;
  int ObjectsIn(ObjectState state) const;
};

std::string ToJson(const ChangeReport& report, const graph::TopoMap& map);
std::string ToHtml(const ChangeReport& report, const graph::TopoMap& map);

// Writes DIR/changes.json and DIR/changes.html, each atomically.
Status WriteChangeReport(const ChangeReport& report, const graph::TopoMap& map, const std::string& folder);

}  // namespace patrolmap::change
