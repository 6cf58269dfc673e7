// FuseItems (report.h): one entry per physical change.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "patrolmap/change/report.h"

namespace patrolmap::change {
namespace {

Eigen::AlignedBox3d Grown(const Eigen::AlignedBox3d& box, double by) {
  return Eigen::AlignedBox3d(box.min().array() - by, box.max().array() + by);
}

// The distance from `point` to the nearest box of `extent` (infinity without one).
double DistanceTo(const std::vector<Eigen::AlignedBox3d>& extent, const Eigen::Vector3d& point) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Eigen::AlignedBox3d& box : extent) nearest = std::min(nearest, box.exteriorDistance(point));
  return nearest;
}

// Whether the segment from `a` to `b` crosses `box` (the slab test).
bool Crosses(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::AlignedBox3d& box) {
  double enter = 0.0, leave = 1.0;
  const Eigen::Vector3d d = b - a;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) < 1e-12) {
      if (a[axis] < box.min()[axis] || a[axis] > box.max()[axis]) return false;
      continue;
    }
    double t0 = (box.min()[axis] - a[axis]) / d[axis], t1 = (box.max()[axis] - a[axis]) / d[axis];
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0), leave = std::min(leave, t1);
    if (enter > leave) return false;
  }
  return true;
}

// Where `item` lies on `entry` (the smaller, the nearer), or none.
std::optional<double> Lies(const ChangeItem& item, const ChangeItem& entry, double distance_m) {
  if (item.kind == "appearance") {
    if (!item.position || !item.bearing) return std::nullopt;
    const Eigen::Vector3d beyond = *item.position + distance_m * item.bearing->direction;
    for (const Eigen::AlignedBox3d& box : entry.extent) {
      if (Crosses(item.bearing->origin, beyond, Grown(box, distance_m)))
        return DistanceTo(entry.extent, *item.position);
    }
    return std::nullopt;
  }
  std::optional<double> nearest;
  for (const Eigen::AlignedBox3d& own : item.extent) {
    for (const Eigen::AlignedBox3d& box : entry.extent) {
      if (!Grown(box, distance_m).intersects(own)) continue;
      const double d = (own.center() - box.center()).norm();
      if (!nearest || d < *nearest) nearest = d;
    }
  }
  return nearest;
}

ChangeEvidence EvidenceOf(const ChangeItem& item) {
  return {item.channels.empty() ? item.kind : item.channels.front(),
          item.id,
          item.kind,
          item.state,
          item.label,
          item.located,
          item.confidence,
          item.position,
          item.source};
}

// `item` joins `entry`: its channel, its finding, its confidence as another witness, its pictures where the entry
// has none. The entry's extent stays its own, so findings do not chain from one change to the next.
void Join(ChangeItem item, ChangeItem* entry) {
  for (const std::string& channel : item.channels) {
    if (std::find(entry->channels.begin(), entry->channels.end(), channel) == entry->channels.end()) {
      entry->channels.push_back(channel);
    }
  }
  entry->confidence = 1.0 - (1.0 - entry->confidence) * (1.0 - item.confidence);
  if (entry->before.image.empty() && !item.before.image.empty()) entry->before = std::move(item.before);
  if (entry->after.image.empty() && !item.after.image.empty()) entry->after = std::move(item.after);
  entry->evidence.push_back(EvidenceOf(item));
}

// Entries in the order objects, geometry regions, appearance: the evidence with the most 3D extent leads.
int Rank(const ChangeItem& item) {
  if (item.kind == "object") return 0;
  return item.kind == "geometry" ? 1 : 2;
}

}  // namespace

std::vector<std::string> IdsOf(const std::vector<ChangeItem>& items, const std::string& list, std::size_t count) {
  std::vector<std::string> ids(count);
  const auto keep = [&](const ReportSource& source, const std::string& id) {
    if (source.list == list && source.index >= 0 && static_cast<std::size_t>(source.index) < count) {
      ids[source.index] = id;
    }
  };
  for (const ChangeItem& item : items) {
    keep(item.source, item.id);
    for (const ChangeEvidence& e : item.evidence) keep(e.source, e.id);
  }
  return ids;
}

std::vector<ChangeItem> FuseItems(std::vector<ChangeItem> items, double fuse_distance_m) {
  std::stable_sort(items.begin(), items.end(),
                   [](const ChangeItem& a, const ChangeItem& b) { return Rank(a) < Rank(b); });
  std::vector<ChangeItem> entries;
  for (ChangeItem& item : items) {
    int target = -1;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t e = 0; e < entries.size() && item.kind != "object"; ++e) {
      const std::optional<double> at = Lies(item, entries[e], fuse_distance_m);
      if (at && *at < nearest) nearest = *at, target = static_cast<int>(e);
    }
    if (target >= 0) {
      Join(std::move(item), &entries[target]);
    } else {
      entries.push_back(std::move(item));
    }
  }
  return entries;
}

}  // namespace patrolmap::change
