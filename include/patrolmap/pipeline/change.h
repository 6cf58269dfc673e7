// Change detection between two patrols (DESIGN.md: prior map -> change report): the comparison of two
// flights of a map. Their patrol records are built in the per-frame pass (patrol_recorder.h).
#pragma once

#include <string>

#include "patrolmap/change/report.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/pipeline/config.h"

namespace patrolmap::pipeline {

// Compares flight `prior` with flight `current` of `map`: appearance at every
// loop closure between their nodes, objects and geometry where both patrol
// records have them. Fails naming a flight that is not in the map.
Status CompareFlights(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                      const change::ChangeOptions& options, change::ChangeReport* report);

// The histories over `map`'s patrols of the site objects `report`'s object changes concern (report.site_objects).
void AddSiteHistories(const graph::TopoMap& map, const change::ObjectDiffOptions& options,
                      change::ChangeReport* report);

// A patrol's change report: between the last flight of `prior` and the last flight of `map` (which extends
// `prior`), written to DIR/changes.json and DIR/changes.html. `compared` (may be null) is false, and nothing
// is written, when `map` adds no flight to a prior that has one. `entries` (may be null) receives the report's
// change list. The last flight's objects take their site ids (change/site_objects.h) from the comparison.
Status ReportLastFlight(const graph::TopoMap& prior, graph::TopoMap* map, const change::ChangeOptions& options,
                        const std::string& folder, change::ChangeReport* report, bool* compared = nullptr,
                        std::vector<change::ChangeItem>* entries = nullptr);

}  // namespace patrolmap::pipeline
