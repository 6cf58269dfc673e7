#include "patrolmap/eval/change_score.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

#include "patrolmap/core/csv.h"

namespace patrolmap::eval {
const TruthObject* FindId(const std::vector<TruthObject>& objects, int id) {
  for (const TruthObject& o : objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

namespace {

constexpr double kSamePlace = 0.05;  // [m]: an object this close to where it was has not moved

struct TruthChange {
  std::string state, label;
  std::optional<Eigen::Vector2d> before, after;
  bool required = true;        // false: reporting it is no error, missing it neither
  bool geometry_only = false;  // the detector saw it too rarely: only a class-agnostic object may report it
  const TruthObject *was = nullptr, *is = nullptr;  // the object before and after (for its footprint)
};

const TruthObject* CentredAt(const std::vector<TruthObject>& objects, const std::optional<Eigen::Vector2d>& centre) {
  if (!centre) return nullptr;
  for (const TruthObject& o : objects) {
    if (o.centre == *centre) return &o;
  }
  return nullptr;
}

// Horizontal distance from `point` to the object's footprint (0 inside it).
double FootprintDistance(const TruthObject& object, const Eigen::Vector3d& point) {
  const Eigen::Vector2d d = point.head<2>() - object.centre;
  const double along = d.x() * std::cos(object.yaw) + d.y() * std::sin(object.yaw);
  const double across = -d.x() * std::sin(object.yaw) + d.y() * std::cos(object.yaw);
  return std::hypot(std::max(0.0, std::abs(along) - object.length / 2),
                    std::max(0.0, std::abs(across) - object.width / 2));
}

// A class-agnostic object lies on the true object (within `distance_m` of its footprint, where it was and where it
// is): changed space shows the part of an object that changed, not its centre. A move must also agree in
// displacement.
double ClassAgnosticDistance(const ReportedObject& r, const TruthChange& t) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double distance = 0.0;
  if (t.before) {
    if (!r.before || t.was == nullptr) return kInfinity;
    distance = std::max(distance, FootprintDistance(*t.was, *r.before));
  }
  if (t.after) {
    if (!r.after || t.is == nullptr) return kInfinity;
    distance = std::max(distance, FootprintDistance(*t.is, *r.after));
  }
  if (t.before && t.after) {
    const Eigen::Vector2d reported = (*r.after - *r.before).head<2>(), truth = *t.after - *t.before;
    distance = std::max(distance, (reported - truth).norm());
  }
  return distance;
}

// The changes the detector saw too rarely to count, as a class-agnostic object (from depth) may still report
// them: optional, and only for class-agnostic reports.
void AddUnseenChanges(const std::vector<TruthObject>& before, const std::vector<TruthObject>& after, int min_detections,
                      std::vector<TruthChange>* truth) {
  for (const TruthObject& b : before) {
    const TruthObject* a = FindId(after, b.id);
    const bool seen_before = b.detections >= min_detections;
    const bool seen_after = a != nullptr && a->detections >= min_detections;
    if (a == nullptr) {
      if (!seen_before) truth->push_back({"removed", b.label, b.centre, std::nullopt, false, true});
    } else if ((a->centre - b.centre).norm() > kSamePlace && !(seen_before && seen_after)) {
      truth->push_back({"moved", b.label, b.centre, a->centre, false, true});
      if (!seen_before) truth->push_back({"removed", b.label, b.centre, std::nullopt, false, true});
      if (!seen_after) truth->push_back({"new", a->label, std::nullopt, a->centre, false, true});
    }
  }
  for (const TruthObject& a : after) {
    if (FindId(before, a.id) == nullptr && a.detections < min_detections) {
      truth->push_back({"new", a.label, std::nullopt, a.centre, false, true});
    }
  }
}

// The true changes as a patrolling robot can know them: an object that moved counts as moved when the
// detector reported it often enough in both flights, as removed when only in the earlier one and as new
// when only in the later one; an object that stayed counts only when seen in both.
std::vector<TruthChange> TruthChanges(const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                                      int min_detections) {
  std::vector<TruthChange> truth;
  for (const TruthObject& b : before) {
    const TruthObject* a = FindId(after, b.id);
    const bool seen_before = b.detections >= min_detections;
    if (a == nullptr) {
      if (seen_before) truth.push_back({"removed", b.label, b.centre, std::nullopt});
      continue;
    }
    const bool seen_after = a->detections >= min_detections;
    const bool moved = (a->centre - b.centre).norm() > kSamePlace;
    if (seen_before && seen_after) {
      truth.push_back({moved ? "moved" : "persistent", b.label, b.centre, a->centre});
    } else if (!moved && b.detections + a->detections > 0) {
      // Stayed, seen too rarely in one flight: persistent if the patrol links the sightings, new if it
      // could not (it never saw it before) — both are right.
      truth.push_back({"persistent", b.label, b.centre, a->centre, false});
      if (seen_after) truth.push_back({"new", a->label, std::nullopt, a->centre, false});
    } else if (moved && seen_before) {
      truth.push_back({"removed", b.label, b.centre, std::nullopt});
    } else if (moved && seen_after) {
      truth.push_back({"new", a->label, std::nullopt, a->centre});
    }
  }
  for (const TruthObject& a : after) {
    if (FindId(before, a.id) == nullptr && a.detections >= min_detections) {
      truth.push_back({"new", a.label, std::nullopt, a.centre});
    }
  }
  return truth;
}

// Distance between a reported and a true change of the same state; infinity when they cannot match.
double ChangeDistance(const ReportedObject& r, const TruthChange& t) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (r.class_agnostic) return ClassAgnosticDistance(r, t);
  if (r.label != t.label || t.geometry_only) return kInfinity;
  double distance = 0.0;
  if (t.before) {
    if (!r.before) return kInfinity;
    distance = std::max(distance, (r.before->head<2>() - *t.before).norm());
  }
  if (t.after) {
    if (!r.after) return kInfinity;
    distance = std::max(distance, (r.after->head<2>() - *t.after).norm());
  }
  return distance;
}

double Ratio(int numerator, int denominator) {
  return denominator > 0 ? static_cast<double>(numerator) / denominator : 0.0;
}

// `point`'s horizontal offset from the object's centre, along its length and across it.
Eigen::Vector2d InBoxFrame(const TruthObject& object, const Eigen::Vector3d& point) {
  const Eigen::Vector2d d = point.head<2>() - object.centre;
  return {d.x() * std::cos(object.yaw) + d.y() * std::sin(object.yaw),
          -d.x() * std::sin(object.yaw) + d.y() * std::cos(object.yaw)};
}

// How far an axis-aligned cube of half side `half` reaches along either horizontal axis of a box turned by `yaw`.
double CubeReach(double yaw, double half) { return half * (std::abs(std::cos(yaw)) + std::abs(std::sin(yaw))); }

// The outcomes of one state: each required true change of it, found (by the report `found_by` names) or missed, and
// each report of it no true change used.
void AddOutcomes(const std::string& state, const std::vector<TruthChange>& truth,
                 const std::vector<ReportedObject>& reported, const std::vector<int>& found_by,
                 const std::vector<bool>& reported_used, std::vector<ObjectOutcome>* outcomes) {
  for (std::size_t t = 0; t < truth.size(); ++t) {
    if (truth[t].state != state || !truth[t].required) continue;
    const char* outcome = found_by[t] >= 0 ? "found" : "missed";
    const TruthObject* object = truth[t].was != nullptr ? truth[t].was : truth[t].is;
    outcomes->push_back({state, outcome, truth[t].label, truth[t].before, truth[t].after, found_by[t],
                         object != nullptr ? object->id : -1});
  }
  const auto flat = [](const std::optional<Eigen::Vector3d>& p) {
    return p ? std::optional<Eigen::Vector2d>(p->head<2>()) : std::nullopt;
  };
  for (std::size_t r = 0; r < reported.size(); ++r) {
    if (reported[r].state != state || reported_used[r]) continue;
    outcomes->push_back(
        {state, "false", reported[r].label, flat(reported[r].before), flat(reported[r].after), static_cast<int>(r)});
  }
}

// Whether `o` stands in `other` too, where it stood: neither gone nor moved.
bool StaysIn(const TruthObject& o, const std::vector<TruthObject>& other) {
  const TruthObject* there = FindId(other, o.id);
  return there != nullptr && (there->centre - o.centre).norm() <= kSamePlace;
}

// The objects of either flight that changed: gone from the other flight, come in it, or moved (both places).
std::vector<TruthObject> MovedOrGone(const std::vector<TruthObject>& before, const std::vector<TruthObject>& after) {
  std::vector<TruthObject> changed;
  for (const auto& [here, other] : {std::pair(&before, &after), std::pair(&after, &before)}) {
    for (const TruthObject& o : *here) {
      if (!StaysIn(o, *other)) changed.push_back(o);
    }
  }
  return changed;
}

}  // namespace

bool TruthObject::Contains(const Eigen::Vector3d& point, double margin) const {
  const Eigen::Vector2d f = InBoxFrame(*this, point);
  return std::abs(f.x()) <= length / 2 + margin && std::abs(f.y()) <= width / 2 + margin && point.z() >= -margin &&
         point.z() <= height + margin;
}

bool TruthObject::Touches(const Eigen::Vector3d& cube_centre, double half) const {
  const Eigen::Vector2d f = InBoxFrame(*this, cube_centre), d = cube_centre.head<2>() - centre;
  const double c = std::abs(std::cos(yaw)), s = std::abs(std::sin(yaw)), reach = half * (c + s);
  return std::abs(f.x()) <= length / 2 + reach && std::abs(f.y()) <= width / 2 + reach &&  // the box's axes
         std::abs(d.x()) <= half + length / 2 * c + width / 2 * s &&                       // the cube's axes
         std::abs(d.y()) <= half + length / 2 * s + width / 2 * c && cube_centre.z() >= -half &&
         cube_centre.z() <= height + half;
}

bool TruthObject::Encloses(const Eigen::Vector3d& cube_centre, double half) const {
  const Eigen::Vector2d f = InBoxFrame(*this, cube_centre);
  const double reach = CubeReach(yaw, half);
  return std::abs(f.x()) <= length / 2 - reach && std::abs(f.y()) <= width / 2 - reach && cube_centre.z() >= half &&
         cube_centre.z() <= height - half;
}

Status ReadTruthObjects(const std::string& log, std::vector<TruthObject>* objects) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& f, TruthObject* o) {
    if (f.size() < 8) return csv.Error("expected 8 columns");
    std::int64_t id = 0;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(f[0], "id", &id));
    o->id = static_cast<int>(id);
    o->label = std::string(f[1]);
    double v[6];
    for (int i = 0; i < 6; ++i) PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(f[2 + i], "pose and size", &v[i]));
    o->centre = Eigen::Vector2d(v[0], v[1]);
    o->yaw = v[2], o->length = v[3], o->width = v[4], o->height = v[5];
    return Status::Ok();
  };
  PATROLMAP_RETURN_IF_ERROR(ReadTable(log + "/groundtruth/objects.csv", nullptr, parse, objects));
  struct Origin {
    TimestampNs timestamp_ns = 0;
    int id = -1;
  };
  const auto parse_origin = [](const CsvReader& csv, const std::vector<std::string_view>& f, Origin* o) {
    if (f.size() < 3) return csv.Error("expected 3 columns");
    std::int64_t id = 0;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(f[0], "timestamp", &o->timestamp_ns));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(f[2], "object_id", &id));
    o->id = static_cast<int>(id);
    return Status::Ok();
  };
  std::vector<Origin> origins;
  PATROLMAP_RETURN_IF_ERROR(ReadTable(log + "/groundtruth/detections.csv", nullptr, parse_origin, &origins));
  std::unordered_map<int, std::vector<TimestampNs>> seen;
  for (const Origin& o : origins) seen[o.id].push_back(o.timestamp_ns);
  for (TruthObject& o : *objects) {
    o.seen_ns = seen[o.id];
    std::sort(o.seen_ns.begin(), o.seen_ns.end());
    o.detections = static_cast<int>(o.seen_ns.size());
  }
  return Status::Ok();
}

double Counts::Precision() const { return Ratio(true_positives, true_positives + false_positives); }
double Counts::Recall() const { return Ratio(true_positives, true_positives + false_negatives); }
double Counts::F1() const {
  const double p = Precision(), r = Recall();
  return p + r > 0 ? 2 * p * r / (p + r) : 0.0;
}
double GeometryScore::Iou() const {
  return Ratio(voxels.true_positives, voxels.true_positives + voxels.false_positives + voxels.false_negatives);
}

ObjectChangeScore ScoreObjectChanges(const std::vector<ReportedObject>& reported,
                                     const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                                     const ChangeScoreOptions& options) {
  ObjectChangeScore score;
  std::vector<TruthChange> truth = TruthChanges(before, after, options.min_detections);
  AddUnseenChanges(before, after, options.min_detections, &truth);
  for (TruthChange& t : truth) t.was = CentredAt(before, t.before), t.is = CentredAt(after, t.after);
  for (const char* state : {"persistent", "new", "removed", "moved"}) {
    struct Candidate {
      double distance;
      std::size_t r, t;
    };
    std::vector<Candidate> candidates;
    int reported_count = 0, truth_count = 0;
    for (std::size_t t = 0; t < truth.size(); ++t) truth_count += truth[t].state == state && truth[t].required;
    for (std::size_t r = 0; r < reported.size(); ++r) {
      if (reported[r].state != state) continue;
      ++reported_count;
      for (std::size_t t = 0; t < truth.size(); ++t) {
        if (truth[t].state != state) continue;
        const double d = ChangeDistance(reported[r], truth[t]);
        if (d <= options.distance_m) candidates.push_back({d, r, t});
      }
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
    std::vector<bool> r_used(reported.size());
    std::vector<int> found_by(truth.size(), -1);  // the report matched to each true change
    Counts& counts = score.by_state[state];
    int optional_matches = 0;
    for (const Candidate& c : candidates) {
      if (r_used[c.r] || found_by[c.t] >= 0) continue;
      r_used[c.r] = true;
      found_by[c.t] = static_cast<int>(c.r);
      ++(truth[c.t].required ? counts.true_positives : optional_matches);
    }
    counts.false_positives = reported_count - counts.true_positives - optional_matches;
    counts.false_negatives = truth_count - counts.true_positives;
    AddOutcomes(state, truth, reported, found_by, r_used, &score.outcomes);
  }
  for (const ReportedObject& r : reported) score.unobserved += r.state == "unobserved";
  return score;
}

GeometryScore ScoreGeometry(const std::vector<Eigen::Vector3i>& changed, const EvidenceGridData& before_grid,
                            const EvidenceGridData& after_grid, const std::vector<TruthObject>& before,
                            const std::vector<TruthObject>& after, const ChangeScoreOptions& options) {
  GeometryScore score;
  const double size = before_grid.voxel_size;
  const auto holds = [](const std::vector<TruthObject>& objects, const Eigen::Vector3d& p, double margin) {
    for (const TruthObject& o : objects) {
      if (o.Contains(p, margin)) return true;
    }
    return false;
  };
  // Core: mostly inside a box of one flight (centre a quarter voxel inside it) and clear of the other
  // flight's boxes, above the ground voxel. Band: touching a box of one flight but not the same box of the
  // other (centre within half a voxel of it).
  const auto core = [&](const Eigen::Vector3d& p) {
    if (p.z() < size / 2) return false;
    return (holds(before, p, -size / 4) && !holds(after, p, size / 2)) ||
           (holds(after, p, -size / 4) && !holds(before, p, size / 2));
  };
  const auto touches = [](const std::vector<TruthObject>& objects, const Eigen::Vector3d& p, double half) {
    return std::any_of(objects.begin(), objects.end(), [&](const TruthObject& o) { return o.Touches(p, half); });
  };
  const auto encloses = [](const std::vector<TruthObject>& objects, const Eigen::Vector3d& p, double half) {
    return std::any_of(objects.begin(), objects.end(), [&](const TruthObject& o) { return o.Encloses(p, half); });
  };
  const auto band = [&](const Eigen::Vector3d& p) {
    return touches(before, p, size / 2) != touches(after, p, size / 2) ||
           encloses(before, p, size / 2) != encloses(after, p, size / 2) || holds(before, p, 0) != holds(after, p, 0);
  };
  const std::vector<TruthObject> moved_or_gone = MovedOrGone(before, after);
  std::vector<VoxelEvidence> predicted;
  for (const Eigen::Vector3i& v : changed) predicted.push_back({v.x(), v.y(), v.z(), 0, 0});
  std::sort(predicted.begin(), predicted.end(), VoxelBefore);
  const auto observed = [&options](const VoxelEvidence& v) { return v.hits + v.passes >= options.min_observations; };
  ForEachCommonVoxel(before_grid, after_grid, [&](const VoxelEvidence& a, const VoxelEvidence& b) {
    if (!observed(a) || !observed(b)) return;
    ++score.observed_voxels;
    const Eigen::Vector3d centre = Eigen::Vector3d(a.x, a.y, a.z) * size;
    const bool is_core = core(centre);
    const bool in_band = is_core || band(centre);
    const bool reported = std::binary_search(predicted.begin(), predicted.end(), a, VoxelBefore);
    if (reported && in_band) ++score.voxels.true_positives;
    if (reported && !in_band) {
      ++score.voxels.false_positives;
      score.false_near_change += holds(moved_or_gone, centre, options.near_change_m);
    }
    if (!reported && is_core) ++score.voxels.false_negatives;
  });
  return score;
}

namespace {

bool SeenNear(const TruthObject& object, TimestampNs time_ns, double within_s) {
  const TimestampNs within = static_cast<TimestampNs>(within_s * 1e9);
  const auto it = std::lower_bound(object.seen_ns.begin(), object.seen_ns.end(), time_ns - within);
  return it != object.seen_ns.end() && *it <= time_ns + within;
}

// The object's box projected into the image, clipped to it; empty when a corner lies behind the camera.
cv::Rect2d ProjectTruthBox(const TruthObject& o, const CameraPoseSample& pose, const CameraIntrinsics& camera,
                           const Distortion& distortion) {
  return ProjectCorners(camera, pose, StandingBoxCorners(o.centre, o.yaw, o.length, o.width, o.height), distortion) &
         cv::Rect2d(0, 0, camera.width, camera.height);
}

bool Overlaps(const cv::Rect2d& a, const cv::Rect2d& b, double min_overlap) {
  const double smaller = std::min(a.area(), b.area());
  return smaller > 0.0 && (a & b).area() >= min_overlap * smaller;
}

}  // namespace

Sightings SightingsOf(const TruthObject& object, const std::vector<CameraPoseSample>& views,
                      const CameraIntrinsics& camera, const Distortion& distortion) {
  Sightings sightings;
  const cv::Rect2d image(0, 0, camera.width, camera.height);
  const Eigen::Vector3d centre(object.centre.x(), object.centre.y(), object.height / 2);
  const std::array<Eigen::Vector3d, 8> corners =
      StandingBoxCorners(object.centre, object.yaw, object.length, object.width, object.height);
  for (const CameraPoseSample& view : views) {
    const double depth = view.ToCamera(centre).z();
    if (depth <= 0.0) continue;
    ++sightings.views;
    const cv::Rect2d box = ProjectCorners(camera, view, corners, distortion);
    if (box.area() <= 0.0 || (box & image) != box) continue;
    sightings.nearest_m = sightings.whole == 0 ? depth : std::min(sightings.nearest_m, depth);
    sightings.farthest_m = std::max(sightings.farthest_m, depth);
    ++sightings.whole;
  }
  return sightings;
}

std::vector<VisibleChange> VisibleChanges(const std::vector<TruthObject>& here, const std::vector<TruthObject>& other,
                                          TimestampNs time_ns, const CameraPoseSample& pose,
                                          const CameraIntrinsics& camera, const ChangeScoreOptions& options,
                                          const Distortion& distortion) {
  std::vector<VisibleChange> changes;
  for (const TruthObject& o : here) {
    if (StaysIn(o, other)) continue;  // unchanged
    if (!SeenNear(o, time_ns, options.visible_within_s)) continue;
    const cv::Rect2d box = ProjectTruthBox(o, pose, camera, distortion);
    if (box.area() >= options.min_area_px) changes.push_back({o.id, box});
  }
  return changes;
}

std::vector<cv::Rect2d> VisibleChangeBoxes(const std::vector<TruthObject>& here, const std::vector<TruthObject>& other,
                                           TimestampNs time_ns, const CameraPoseSample& pose,
                                           const CameraIntrinsics& camera, const ChangeScoreOptions& options,
                                           const Distortion& distortion) {
  std::vector<cv::Rect2d> boxes;
  for (const VisibleChange& c : VisibleChanges(here, other, time_ns, pose, camera, options, distortion)) {
    boxes.push_back(c.box);
  }
  return boxes;
}

bool CentreMapsInside(const Eigen::Matrix3d& to_other, int width, int height, const cv::Rect2d& box) {
  const Eigen::Vector3d p = to_other * Eigen::Vector3d(box.x + box.width / 2, box.y + box.height / 2, 1.0);
  if (p.z() <= 0.0) return false;
  const double u = p.x() / p.z(), v = p.y() / p.z();
  return u >= 0.0 && v >= 0.0 && u < width && v < height;
}

void KeepInOverlap(const Eigen::Matrix3d& to_other, int width, int height, std::vector<cv::Rect2d>* boxes) {
  const auto outside = [&](const cv::Rect2d& box) { return !CentreMapsInside(to_other, width, height, box); };
  boxes->erase(std::remove_if(boxes->begin(), boxes->end(), outside), boxes->end());
}

double AppearanceScore::Precision() const { return Ratio(regions_on_change, regions); }
double AppearanceScore::Recall() const { return Ratio(changes_found, changes); }

AppearanceScore ScoreAppearance(const std::vector<PlaceTruth>& truth,
                                const std::vector<std::vector<RegionBoxes>>& regions,
                                const ChangeScoreOptions& options) {
  AppearanceScore score;
  for (std::size_t p = 0; p < truth.size() && p < regions.size(); ++p) {
    const PlaceTruth& t = truth[p];
    const auto on = [&](const RegionBoxes& r, const cv::Rect2d& box, bool prior) {
      return Overlaps(prior ? r.prior : r.current, box, options.min_overlap);
    };
    for (const RegionBoxes& r : regions[p]) {
      ++score.regions;
      const bool hit =
          std::any_of(t.prior.begin(), t.prior.end(), [&](const cv::Rect2d& b) { return on(r, b, true); }) ||
          std::any_of(t.current.begin(), t.current.end(), [&](const cv::Rect2d& b) { return on(r, b, false); });
      score.regions_on_change += hit;
    }
    for (const bool prior : {true, false}) {
      for (const cv::Rect2d& box : prior ? t.prior : t.current) {
        ++score.changes;
        score.changes_found +=
            std::any_of(regions[p].begin(), regions[p].end(), [&](const RegionBoxes& r) { return on(r, box, prior); });
      }
    }
  }
  return score;
}

double RouteScore::Precision() const { return Ratio(changes_on_truth, changes); }
double RouteScore::Recall() const { return Ratio(found, visible); }

double AveragePrecision(std::vector<std::pair<double, bool>> ranked) {
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
  int true_so_far = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    if (!ranked[i].second) continue;
    ++true_so_far;
    sum += static_cast<double>(true_so_far) / (i + 1);
  }
  return true_so_far > 0 ? sum / true_so_far : 0.0;
}

RouteScore ScoreRoute(const std::vector<RoutePairTruth>& truth, const std::vector<ReportedRouteChange>& reported,
                      const std::vector<RouteCandidate>& candidates, const ChangeScoreOptions& options) {
  RouteScore score;
  // Every object change visible in some compared pair, on either side: (side, object id) -> found.
  std::map<std::pair<bool, int>, bool> visible;
  for (const RoutePairTruth& t : truth) {
    for (const bool prior : {true, false}) {
      for (const VisibleChange& c : prior ? t.prior : t.current) visible.emplace(std::make_pair(prior, c.id), false);
    }
  }
  for (const ReportedRouteChange& change : reported) {
    ++score.changes;
    bool on_truth = false;
    for (std::size_t v = 0; v < change.pairs.size(); ++v) {
      const int pair = change.pairs[v];
      if (pair < 0 || pair >= static_cast<int>(truth.size())) continue;
      for (const bool prior : {true, false}) {
        const cv::Rect2d& box = prior ? change.boxes[v].prior : change.boxes[v].current;
        for (const VisibleChange& c : prior ? truth[pair].prior : truth[pair].current) {
          if (!Overlaps(box, c.box, options.min_overlap)) continue;
          on_truth = true;
          visible[{prior, c.id}] = true;
        }
      }
    }
    score.changes_on_truth += on_truth;
    score.ranked.emplace_back(change.confidence, on_truth);
  }
  score.visible = static_cast<int>(visible.size());
  for (const auto& [change, found] : visible) {
    score.found += found;
    score.visible_in_prior += change.first;
    score.found_in_prior += change.first && found;
  }
  std::map<std::pair<bool, int>, const RouteCandidate*> furthest;  // per object change not found
  for (const RouteCandidate& candidate : candidates) {
    if (candidate.pair < 0 || candidate.pair >= static_cast<int>(truth.size())) continue;
    for (const bool prior : {true, false}) {
      const cv::Rect2d& box = prior ? candidate.boxes.prior : candidate.boxes.current;
      for (const VisibleChange& c : prior ? truth[candidate.pair].prior : truth[candidate.pair].current) {
        if (visible[{prior, c.id}] || !Overlaps(box, c.box, options.min_overlap)) continue;
        const RouteCandidate*& best = furthest[{prior, c.id}];
        if (best == nullptr || candidate.step > best->step) best = &candidate;
      }
    }
  }
  for (const auto& [change, found] : visible) {
    if (found) continue;
    const auto it = furthest.find(change);
    ++score.lost_at[it != furthest.end() ? it->second->step_name : "no_region"];
  }
  return score;
}

std::vector<TrueChange> TrueChanges(const std::vector<TruthObject>& before, const std::vector<TruthObject>& after) {
  std::vector<TrueChange> changes;
  for (const TruthObject& b : before) {
    const TruthObject* a = FindId(after, b.id);
    if (a == nullptr) changes.push_back({b.id, "removed", &b, nullptr});
    if (a != nullptr && (a->centre - b.centre).norm() > kSamePlace) changes.push_back({b.id, "moved", &b, a});
  }
  for (const TruthObject& a : after) {
    if (FindId(before, a.id) == nullptr) changes.push_back({a.id, "new", nullptr, &a});
  }
  return changes;
}

double EntryScore::Precision() const { return Ratio(true_entries, true_entries + static_cast<int>(false_ids.size())); }
double EntryScore::Recall(bool observable_only) const { return (observable_only ? observable : all).Recall(); }
double EntryScore::F1(bool observable_only) const {
  const double p = Precision(), r = Recall(observable_only);
  return p + r > 0.0 ? 2.0 * p * r / (p + r) : 0.0;
}

EntryScore ScoreEntries(const std::vector<ReportedEntry>& entries, const std::vector<TrueChange>& truth,
                        const ChangeScoreOptions& options) {
  EntryScore score;
  score.entries = static_cast<int>(entries.size());
  std::vector<bool> found(truth.size(), false);
  for (const ReportedEntry& entry : entries) {
    if (!entry.position) {
      ++score.bearings;
      continue;
    }
    bool on_truth = false;
    for (std::size_t t = 0; t < truth.size(); ++t) {
      for (const std::optional<Eigen::Vector3d>& p : {entry.position, entry.from}) {
        if (!p) continue;
        for (const TruthObject* end : {truth[t].before, truth[t].after}) {
          if (end != nullptr && end->Contains(*p, options.distance_m)) on_truth = found[t] = true;
        }
      }
    }
    if (on_truth) ++score.true_entries;
    if (!on_truth) score.false_ids.push_back(entry.id);
  }
  const int false_entries = static_cast<int>(score.false_ids.size());
  score.all.false_positives = score.observable.false_positives = false_entries;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    (found[t] ? score.all.true_positives : score.all.false_negatives) += 1;
    if (truth[t].observable) (found[t] ? score.observable.true_positives : score.observable.false_negatives) += 1;
    if (!found[t]) score.missed_ids.push_back(truth[t].id);
  }
  return score;
}

ObjectChangeTotals TotalObjectChanges(const ObjectChangeScore& score, const std::vector<TrueChange>& truth) {
  ObjectChangeTotals totals;
  for (const ObjectOutcome& o : score.outcomes) {
    if (o.outcome == "false" && o.state != "persistent") ++totals.all.false_positives;
  }
  totals.observable.false_positives = totals.all.false_positives;
  for (const TrueChange& change : truth) {
    const bool found = std::any_of(score.outcomes.begin(), score.outcomes.end(), [&](const ObjectOutcome& o) {
      return o.outcome == "found" && o.id == change.id && o.state == change.state;
    });
    (found ? totals.all.true_positives : totals.all.false_negatives) += 1;
    if (change.observable) (found ? totals.observable.true_positives : totals.observable.false_negatives) += 1;
  }
  return totals;
}

double SiteIdScore::Persistence() const { return tracked > 0 ? static_cast<double>(kept) / tracked : 1.0; }

int TruthIdOf(const MapObject& object, const std::vector<TruthObject>& truth, const ChangeScoreOptions& options) {
  int best = -1;
  double nearest = 0.0;
  for (const TruthObject& t : truth) {
    if (t.label != object.label || !t.Contains(object.centroid, options.distance_m)) continue;
    const double d = (object.centroid.head<2>() - t.centre).norm();
    if (best < 0 || d < nearest) best = t.id, nearest = d;
  }
  return best;
}

SiteIdScore ScoreSiteIds(const std::vector<std::vector<std::pair<int, int>>>& patrols) {
  SiteIdScore score;
  std::map<int, std::set<int>> truths_of_site;
  for (std::size_t p = 0; p < patrols.size(); ++p) {
    std::map<int, int> site_of_truth;  // this patrol's
    for (const auto& [site, truth] : patrols[p]) {
      if (site < 0 || truth < 0) continue;
      truths_of_site[site].insert(truth);
      site_of_truth.emplace(truth, site);
    }
    if (p == 0) continue;
    std::map<int, int> before;
    for (const auto& [site, truth] : patrols[p - 1]) {
      if (site >= 0 && truth >= 0) before.emplace(truth, site);
    }
    for (const auto& [truth, site] : site_of_truth) {
      const auto was = before.find(truth);
      if (was == before.end()) continue;
      ++score.tracked;
      (was->second == site ? score.kept : score.changed) += 1;
    }
  }
  for (const auto& [site, truths] : truths_of_site) score.merged += truths.size() > 1;
  return score;
}

}  // namespace patrolmap::eval
