#include "patrolmap/change/object_diff.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

constexpr double kMinClearance = 1.0;  // voxels this close to an object do not hide it, nor within its half size [m]

bool Occupied(const EvidenceGridData& grid, const Eigen::Vector3d& point) {
  return IsOccupied(FindVoxel(grid, VoxelIndex(point, grid.voxel_size)));
}

// Whether an occupied voxel lies on the line of sight short of `clearance` before the object: what stands
// where the object stood (another object, the object moved by a little) does not hide its place, nor do
// voxels inside `see_through` (the boxes of current objects that may be this one, moved).
bool Hidden(const EvidenceGridData& grid, const Eigen::Vector3d& from, const Eigen::Vector3d& to, double clearance,
            const std::vector<const MapObject*>& see_through) {
  static constexpr double kBoxMargin = 0.3;  // [m]
  const double length = (to - from).norm() - clearance;
  const Eigen::Vector3d direction = (to - from).normalized();
  for (double s = grid.voxel_size; s < length; s += grid.voxel_size) {
    const Eigen::Vector3d point = from + s * direction;
    if (!Occupied(grid, point)) continue;
    const bool inside = std::any_of(see_through.begin(), see_through.end(), [&point](const MapObject* o) {
      return (point.array() >= o->box_min.array() - kBoxMargin).all() &&
             (point.array() <= o->box_max.array() + kBoxMargin).all();
    });
    if (!inside) return true;
  }
  return false;
}

}  // namespace

AppearanceTerms CompareAppearance(const MapObject& a, const MapObject& b) {
  AppearanceTerms terms;
  if (a.descriptor.size() >= kOrientationBins && b.descriptor.size() >= kOrientationBins) {
    double l1 = 0.0;
    for (std::size_t i = 0; i < kOrientationBins; ++i) l1 += std::abs(a.descriptor[i] - b.descriptor[i]);
    terms.texture = 0.5 * l1;
  }
  if (a.descriptor.size() > kBrightnessRankAt && b.descriptor.size() > kBrightnessRankAt) {
    terms.brightness = std::abs(a.descriptor[kBrightnessRankAt] - b.descriptor[kBrightnessRankAt]);
  }
  if (a.height > 0.0 && b.height > 0.0) terms.height = std::abs(a.height - b.height) / std::max(a.height, b.height);
  return terms;
}

double AppearanceTerms::Distance() const {
  double sum = 0.0;
  int count = 0;
  for (const std::optional<double>& term : {texture, brightness, height}) {
    if (term) sum += *term, ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

namespace {

Eigen::Vector3d MeanOf(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return sum / static_cast<double>(points.size());
}

// Principal axes, each signed so that the points' third moment along it is positive.
Eigen::Matrix3d SignedAxes(const std::vector<Eigen::Vector3f>& points) {
  const Eigen::Vector3d mean = MeanOf(points);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& p : points)
    covariance += (p.cast<double>() - mean) * (p.cast<double>() - mean).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU);
  Eigen::Matrix3d axes = svd.matrixU();
  for (int k = 0; k < 3; ++k) {
    double skew = 0.0;
    for (const Eigen::Vector3f& p : points) skew += std::pow((p.cast<double>() - mean).dot(axes.col(k)), 3);
    if (skew < 0) axes.col(k) *= -1.0;
  }
  return axes;
}

struct Pair {
  int prior, current;
  double cost;
};

// Indices of points sorted by their x coordinate: the ones within `range` of a point, in index order, found without
// looking at all (a long patrol has thousands of views and objects, and each object is compared only nearby).
class ByX {
 public:
  template <typename Item, typename Position>
  ByX(const std::vector<Item>& items, Position position) : order_(items.size()), x_(items.size()) {
    for (std::size_t k = 0; k < items.size(); ++k) order_[k] = static_cast<int>(k);
    std::sort(order_.begin(), order_.end(),
              [&](int a, int b) { return position(items[a]).x() < position(items[b]).x(); });
    for (std::size_t k = 0; k < order_.size(); ++k) x_[k] = position(items[order_[k]]).x();
  }

  // The indices whose x lies within `range` of `x` (a little more, so that rounding drops none), ascending: a
  // superset of those within `range` in space, which the caller then tests as before.
  std::vector<int> Near(double x, double range) const {
    const double padded = range * (1.0 + 1e-9) + 1e-9;
    const auto first = std::lower_bound(x_.begin(), x_.end(), x - padded);
    const auto last = std::upper_bound(x_.begin(), x_.end(), x + padded);
    std::vector<int> near;
    near.reserve(static_cast<std::size_t>(last - first));
    for (auto it = first; it != last; ++it) near.push_back(order_[it - x_.begin()]);
    std::sort(near.begin(), near.end());
    return near;
  }

 private:
  std::vector<int> order_;
  std::vector<double> x_;
};

ByX ViewsByX(const PatrolRecord& patrol) {
  return ByX(patrol.views, [](const CameraPoseSample& view) { return view.position; });
}

ByX ObjectsByX(const std::vector<MapObject>& objects) {
  return ByX(objects, [](const MapObject& object) { return object.centroid; });
}

// A change that involves a prior object (`prior` may be null for new ones) and a current one (may be null).
ObjectChange MakeChange(ObjectState state, const MapObject* prior, const MapObject* current, double confidence,
                        int covering_views = 0) {
  ObjectChange change;
  change.state = state;
  change.label = prior != nullptr ? prior->label : current->label;
  change.confidence = confidence;
  change.covering_views = covering_views;
  if (prior != nullptr) change.prior_id = prior->id, change.before = prior->centroid;
  if (current != nullptr) change.current_id = current->id, change.after = current->centroid;
  return change;
}

// Greedy assignment in ascending cost.
void AssignGreedy(std::vector<Pair> pairs, std::vector<bool>* prior_used, std::vector<bool>* current_used,
                  std::vector<Pair>* chosen) {
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.cost < b.cost; });
  for (const Pair& pair : pairs) {
    if ((*prior_used)[pair.prior] || (*current_used)[pair.current]) continue;
    (*prior_used)[pair.prior] = (*current_used)[pair.current] = true;
    chosen->push_back(pair);
  }
}

}  // namespace

const char* ToString(ObjectState state) {
  switch (state) {
    case ObjectState::kPersistent: return "persistent";
    case ObjectState::kNew: return "new";
    case ObjectState::kRemoved: return "removed";
    case ObjectState::kMoved: return "moved";
    case ObjectState::kUnobserved: return "unobserved";
  }
  return "?";
}

bool ParseObjectState(const std::string& text, ObjectState* state) {
  for (ObjectState s : {ObjectState::kPersistent, ObjectState::kNew, ObjectState::kRemoved, ObjectState::kMoved,
                        ObjectState::kUnobserved}) {
    if (text == ToString(s)) return *state = s, true;
  }
  return false;
}

Eigen::Matrix3d RegisterRotation(const std::vector<Eigen::Vector3f>& before,
                                 const std::vector<Eigen::Vector3f>& after) {
  if (before.size() < 10 || after.size() < 10) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation = SignedAxes(after) * SignedAxes(before).transpose();
  if (rotation.determinant() < 0) {  // a reflection: flip the least certain axis
    Eigen::Matrix3d a = SignedAxes(after);
    a.col(2) *= -1.0;
    rotation = a * SignedAxes(before).transpose();
  }
  return rotation;
}

double VisibleFraction(const MapObject& object, const CameraIntrinsics& camera, const CameraPoseSample& view) {
  const cv::Rect2d box = ProjectBox(camera, view, object.box_min, object.box_max);
  if (box.area() <= 0.0) return 0.0;
  return (box & cv::Rect2d(0, 0, camera.width, camera.height)).area() / box.area();
}

namespace {

// CoveringViews over the views `by_x` finds near the object.
int CoveringViewsNear(const MapObject& object, const PatrolRecord& patrol, const ByX& by_x,
                      const ObjectDiffOptions& options, const std::vector<const MapObject*>& see_through) {
  const bool grid = patrol.grid.voxel_size > 0.0 && !patrol.grid.voxels.empty();
  const double clearance = std::max(kMinClearance, 0.5 * (object.box_max - object.box_min).norm());
  int views = 0;
  for (const int k : by_x.Near(object.centroid.x(), options.max_visible_range_m)) {
    const CameraPoseSample& view = patrol.views[k];
    const Eigen::Vector3d c = view.ToCamera(object.centroid);
    if (c.z() < 0.3 || c.norm() > options.max_visible_range_m) continue;
    if (VisibleFraction(object, patrol.camera, view) < options.min_visible_fraction) continue;
    if (grid && Hidden(patrol.grid, view.position, object.centroid, clearance, see_through)) continue;
    ++views;
  }
  return views;
}

}  // namespace

int CoveringViews(const MapObject& object, const PatrolRecord& patrol, const ObjectDiffOptions& options,
                  const std::vector<const MapObject*>& see_through) {
  return CoveringViewsNear(object, patrol, ViewsByX(patrol), options, see_through);
}

double ExpectedDetections(const MapObject& object, int own_views, int views) {
  return own_views > 0 ? object.detections * static_cast<double>(views) / own_views : static_cast<double>(views);
}

namespace {

// The two object maps being compared and which of their objects a state has taken.
struct Matching {
  const std::vector<MapObject>& p;
  const std::vector<MapObject>& c;
  std::vector<bool> prior_used, current_used;
  std::vector<int> views;                      // covering views of each prior object (those not persistent) ...
  std::vector<double> expected;                // ... and the detections they would have given
  std::vector<double> prior_top, current_top;  // 95th percentile of the points' height; 0 without points
  std::vector<std::pair<int, int>> movable;    // (prior, current) pairs that may be one object moved
  ByX current_by_x;                            // the current objects, and the views of both patrols, by x
  ByX prior_views, current_views;
};

Matching StartMatching(const PatrolRecord& prior, const PatrolRecord& current) {
  Matching m{prior.objects,
             current.objects,
             std::vector<bool>(prior.objects.size(), false),
             std::vector<bool>(current.objects.size(), false),
             {},
             {},
             {},
             {},
             {},
             ObjectsByX(current.objects),
             ViewsByX(prior),
             ViewsByX(current)};
  for (const MapObject& o : m.p) m.prior_top.push_back(PointQuantile(o.points, 2, 0.95));
  for (const MapObject& o : m.c) m.current_top.push_back(PointQuantile(o.points, 2, 0.95));
  return m;
}

// Persistent: same label and close; nearest first. (Paper 000's point-pair test on top of it changed nothing on
// held-out series: detections of one label a metre apart are the same object.)
void MatchPersistent(const ObjectDiffOptions& options, Matching* m, std::vector<ObjectChange>* changes) {
  std::vector<Pair> close, persistent;
  for (std::size_t i = 0; i < m->p.size(); ++i) {
    for (const int j : m->current_by_x.Near(m->p[i].centroid.x(), options.match_distance_m)) {
      const MapObject &a = m->p[i], &b = m->c[j];
      const double distance = (a.centroid - b.centroid).norm();
      if (a.label != b.label || distance > options.match_distance_m) continue;
      close.push_back({static_cast<int>(i), j, distance});
    }
  }
  AssignGreedy(close, &m->prior_used, &m->current_used, &persistent);
  for (const Pair& pair : persistent) {
    const MapObject &a = m->p[pair.prior], &b = m->c[pair.current];
    if (!a.confirmed && !b.confirmed) continue;
    const double confidence =
        std::min(a.confidence, b.confidence) * (1.0 - pair.cost / (2.0 * options.match_distance_m));
    changes->push_back(MakeChange(ObjectState::kPersistent, &a, &b, confidence));
  }
}

// Whether unmatched current object j may be unmatched prior object i moved: same label, within max_move_m,
// and alike in top height. (A shape test after the move, paper 000's point-pair test on the shifted
// points, lost two of ten moves on held-out series: a detected object's points are the sides one flight saw.)
bool MayHaveMoved(const ObjectDiffOptions& options, const Matching& m, std::size_t i, std::size_t j) {
  if (m.prior_used[i] || m.current_used[j] || m.p[i].label != m.c[j].label) return false;
  if ((m.p[i].centroid - m.c[j].centroid).norm() > options.max_move_m) return false;
  return m.prior_top[i] <= 0.0 || m.current_top[j] <= 0.0 ||
         std::abs(m.prior_top[i] - m.current_top[j]) <= options.max_top_difference_m;
}

// How well the current patrol saw the place of every unmatched prior object: its covering views there and the
// detections they would have given, at the rate the prior patrol detected the object in its own covering views.
// Unconfirmed objects only explained sightings as persistent; they take no other state. Also finds the pairs
// that may be one object moved (the move candidates, and what the visibility test looks through).
void MeasureCoverage(const PatrolRecord& prior, const PatrolRecord& current, const ObjectDiffOptions& options,
                     Matching* m) {
  m->views.assign(m->p.size(), 0);
  m->expected.assign(m->p.size(), 0.0);
  for (std::size_t i = 0; i < m->p.size(); ++i) m->prior_used[i] = m->prior_used[i] || !m->p[i].confirmed;
  for (std::size_t j = 0; j < m->c.size(); ++j) m->current_used[j] = m->current_used[j] || !m->c[j].confirmed;
  for (std::size_t i = 0; i < m->p.size(); ++i) {
    if (m->prior_used[i]) continue;
    std::vector<const MapObject*> candidates;  // unmatched current objects that may be this one, moved
    for (const int j : m->current_by_x.Near(m->p[i].centroid.x(), options.max_move_m)) {
      if (!MayHaveMoved(options, *m, i, j)) continue;
      m->movable.emplace_back(static_cast<int>(i), j);
      candidates.push_back(&m->c[j]);
    }
    m->views[i] = CoveringViewsNear(m->p[i], current, m->current_views, options, candidates);
    m->expected[i] =
        ExpectedDetections(m->p[i], CoveringViewsNear(m->p[i], prior, m->prior_views, options, {}), m->views[i]);
  }
}

// Move candidates (paper 003): the pairs that may be one object moved, ordered by the weighted,
// min-max normalised physical and appearance distances. The normalised distance only orders them: the
// worst candidate always scores 1, so the gates are absolute.
std::vector<Pair> MoveCandidates(const ObjectDiffOptions& options, const Matching& m) {
  std::vector<Pair> candidates;
  std::vector<double> physical, appearance;
  for (const auto& [i, j] : m.movable) {
    candidates.push_back({i, j, 0.0});
    physical.push_back((m.p[i].centroid - m.c[j].centroid).norm());
    appearance.push_back(CompareAppearance(m.p[i], m.c[j]).Distance());
  }
  const auto normalise = [](const std::vector<double>& values, std::size_t k) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    return *hi - *lo > 1e-12 ? (values[k] - *lo) / (*hi - *lo) : 0.0;
  };
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    candidates[k].cost =
        options.physical_weight * normalise(physical, k) + (1.0 - options.physical_weight) * normalise(appearance, k);
  }
  return candidates;
}

void MatchMoved(const ObjectDiffOptions& options, Matching* m, std::vector<ObjectChange>* changes) {
  std::vector<Pair> moved;
  AssignGreedy(MoveCandidates(options, *m), &m->prior_used, &m->current_used, &moved);
  for (const Pair& pair : moved) {
    const MapObject &a = m->p[pair.prior], &b = m->c[pair.current];
    ObjectChange change =
        MakeChange(ObjectState::kMoved, &a, &b, std::min(a.confidence, b.confidence) * (1.0 - 0.5 * pair.cost),
                   m->views[pair.prior]);
    change.expected_detections = m->expected[pair.prior];
    change.weighted_distance = pair.cost;
    change.rotation = RegisterRotation(a.points, b.points);
    changes->push_back(change);
  }
}

}  // namespace

std::vector<ObjectChange> DiffObjects(const PatrolRecord& prior, const PatrolRecord& current,
                                      const ObjectDiffOptions& options) {
  Matching m = StartMatching(prior, current);
  std::vector<ObjectChange> changes;
  MatchPersistent(options, &m, &changes);
  MeasureCoverage(prior, current, options, &m);
  MatchMoved(options, &m, &changes);
  for (std::size_t i = 0; i < m.p.size(); ++i) {
    if (m.prior_used[i]) continue;
    // The chance that the object, still in place, would have been detected: 1 - exp(-expected detections).
    const bool seen = m.expected[i] >= options.min_expected_detections;
    const double confidence = m.p[i].confidence * (seen ? 1.0 - std::exp(-m.expected[i]) : 1.0);
    ObjectChange change =
        MakeChange(seen ? ObjectState::kRemoved : ObjectState::kUnobserved, &m.p[i], nullptr, confidence, m.views[i]);
    change.expected_detections = m.expected[i];
    changes.push_back(change);
  }
  for (std::size_t j = 0; j < m.c.size(); ++j) {
    if (m.current_used[j]) continue;
    const double confidence = m.c[j].confidence * std::min(1.0, m.c[j].detections / 10.0);
    changes.push_back(MakeChange(ObjectState::kNew, nullptr, &m.c[j], confidence));
  }
  return changes;
}

}  // namespace patrolmap::change
