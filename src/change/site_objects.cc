#include "patrolmap/change/site_objects.h"

#include <algorithm>

namespace patrolmap::change {
namespace {

MapObject* FindObject(PatrolRecord* record, int id) {
  for (MapObject& o : record->objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

const MapObject* FindObject(const PatrolRecord& record, int id) {
  for (const MapObject& o : record.objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

}  // namespace

int LargestSiteId(const graph::TopoMap& map) {
  int largest = 0;
  for (const PatrolRecord& record : map.patrols()) {
    for (const MapObject& o : record.objects) largest = std::max(largest, o.site_id);
  }
  return largest;
}

void NumberSiteObjects(PatrolRecord* record, int* last) {
  for (MapObject& o : record->objects) {
    if (o.site_id < 0) o.site_id = ++*last;
  }
}

void CarrySiteObjects(const PatrolRecord& prior, const ChangeReport& report, PatrolRecord* current, int* last) {
  for (MapObject& o : current->objects) o.site_id = -1;
  for (const ObjectChange& change : report.objects) {
    if (change.class_agnostic || (change.state != ObjectState::kPersistent && change.state != ObjectState::kMoved))
      continue;
    const MapObject* before = FindObject(prior, change.prior_id);
    MapObject* now = FindObject(current, change.current_id);
    if (before != nullptr && now != nullptr && before->site_id >= 0) now->site_id = before->site_id;
  }
  NumberSiteObjects(current, last);
}

void NumberAllSiteObjects(graph::TopoMap* map) {
  int last = LargestSiteId(*map);
  for (const std::string& flight : map->Flights()) {
    if (PatrolRecord* record = map->MutablePatrol(flight)) NumberSiteObjects(record, &last);
  }
}

void NameSiteObjects(const PatrolRecord& prior, const PatrolRecord& current, ChangeReport* report) {
  for (ObjectChange& change : report->objects) {
    if (change.class_agnostic) continue;
    const MapObject* before = FindObject(prior, change.prior_id);
    const MapObject* now = FindObject(current, change.current_id);
    change.site_id = before != nullptr && before->site_id >= 0 ? before->site_id : now != nullptr ? now->site_id : -1;
  }
}

}  // namespace patrolmap::change
