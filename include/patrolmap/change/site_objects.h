// Site objects: one id for the same physical object across a map's patrols. A map's first patrol numbers its
// objects 1, 2, ...; a later patrol's object that the comparison with the patrol before it found persistent or
// moved keeps that object's id, and every other object of it (new, or one the comparison could not judge) takes
// the next free id. Maps written before site ids number their objects when next patrolled, in the order flown.
#pragma once

#include "patrolmap/change/report.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

// The largest site id among the objects of `map`'s patrols; 0 when none has one.
int LargestSiteId(const graph::TopoMap& map);

// Gives every object of `record` without a site id the next one after `*last` (which it advances).
void NumberSiteObjects(PatrolRecord* record, int* last);

// `current`'s site ids from `report` (the comparison of `prior` with `current`): an object the report found
// persistent or moved keeps its prior object's id; the others are numbered after `*last`.
void CarrySiteObjects(const PatrolRecord& prior, const ChangeReport& report, PatrolRecord* current, int* last);

// Numbers every object of `map`'s patrols that has no site id yet, in the order flown.
void NumberAllSiteObjects(graph::TopoMap* map);

// Sets each detected object change's site_id from the two records (the prior object's, else the current's).
void NameSiteObjects(const PatrolRecord& prior, const PatrolRecord& current, ChangeReport* report);

}  // namespace patrolmap::change
