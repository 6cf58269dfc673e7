#include "patrolmap/change/object_diff.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

constexpr double kPairDistance = 0.25;      // point-pair test between patrols [m]
constexpr double kMinPairFraction = 0.5;
constexpr double kMinClearance = 1.0;       // voxels this close to an object do not hide it, nor within its half size [m]

// A voxel counts as occupied when most rays ended in it and at least two did.
bool Occupied(const EvidenceGridData& grid, const Eigen::Vector3d& point) {
  const VoxelEvidence* v = FindVoxel(grid, VoxelIndex(point, grid.voxel_size));
  return v != nullptr && v->hits >= 2 && v->hits > v->passes;
}

// Whether an occupied voxel lies on the line of sight short of `clearance` before the object: what stands
// where the object stood (another object, the object moved by a little) does not hide its place.
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
      return (point.array() >= o->box_min.array() - kBoxMargin).all() && (point.array() <= o->box_max.array() + kBoxMargin).all();
    });
    if (!inside) return true;
  }
  return false;
}

}  // namespace

AppearanceTerms CompareAppearance(const MapObject& a, const MapObject& b) {
  AppearanceTerms terms;
  constexpr std::size_t kBins = 8;
  if (a.descriptor.size() >= kBins && b.descriptor.size() >= kBins) {
    double l1 = 0.0;
    for (std::size_t i = 0; i < kBins; ++i) l1 += std::abs(a.descriptor[i] - b.descriptor[i]);
    terms.texture = 0.5 * l1;
  }
  if (a.descriptor.size() > kBins && b.descriptor.size() > kBins) {
    terms.brightness = std::abs(a.descriptor[kBins] - b.descriptor[kBins]);
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
  for (const Eigen::Vector3f& p : points) covariance += (p.cast<double>() - mean) * (p.cast<double>() - mean).transpose();
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

Eigen::Matrix3d RegisterRotation(const std::vector<Eigen::Vector3f>& before, const std::vector<Eigen::Vector3f>& after) {
  if (before.size() < 10 || after.size() < 10) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation = SignedAxes(after) * SignedAxes(before).transpose();
  if (rotation.determinant() < 0) {  // a reflection: flip the least certain axis
    Eigen::Matrix3d a = SignedAxes(after);
    a.col(2) *= -1.0;
    rotation = a * SignedAxes(before).transpose();
  }
  return rotation;
}

int CoveringViews(const MapObject& object, const PatrolRecord& current, const ObjectDiffOptions& options,
                  const std::vector<const MapObject*>& see_through) {
  const CameraIntrinsics& camera = current.camera;
  const bool grid = current.grid.voxel_size > 0.0 && !current.grid.voxels.empty();
  const double clearance = std::max(kMinClearance, 0.5 * (object.box_max - object.box_min).norm());
  int views = 0;
  for (const CameraPoseSample& view : current.views) {
    const Eigen::Vector3d c = view.ToCamera(object.centroid);
    if (c.z() < 0.3 || c.norm() > options.max_visible_range_m) continue;
    const double u = camera.fx * c.x() / c.z() + camera.cx, v = camera.fy * c.y() / c.z() + camera.cy;
    const double m = options.image_margin_px;
    if (u < m || v < m || u > camera.width - 1 - m || v > camera.height - 1 - m) continue;
    if (grid && Hidden(current.grid, view.position, object.centroid, clearance, see_through)) continue;
    ++views;
  }
  return views;
}

std::vector<ObjectChange> DiffObjects(const PatrolRecord& prior, const PatrolRecord& current,
                                      const ObjectDiffOptions& options) {
  const std::vector<MapObject>& p = prior.objects;
  const std::vector<MapObject>& c = current.objects;
  std::vector<bool> prior_used(p.size(), false), current_used(c.size(), false);
  std::vector<ObjectChange> changes;

  // Persistent: same label, close, and (with points) passing the point-pair test.
  std::vector<Pair> close, persistent;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < c.size(); ++j) {
      const double distance = (p[i].centroid - c[j].centroid).norm();
      if (p[i].label != c[j].label || distance > options.match_distance_m) continue;
      if (!p[i].points.empty() && !c[j].points.empty() &&
          PairFraction(c[j].points, p[i].points, kPairDistance) < kMinPairFraction) {
        continue;
      }
      close.push_back({static_cast<int>(i), static_cast<int>(j), distance});
    }
  }
  AssignGreedy(close, &prior_used, &current_used, &persistent);
  for (const Pair& pair : persistent) {
    ObjectChange change;
    change.state = ObjectState::kPersistent;
    change.label = p[pair.prior].label;
    change.prior_id = p[pair.prior].id, change.current_id = c[pair.current].id;
    change.before = p[pair.prior].centroid, change.after = c[pair.current].centroid;
    change.confidence = std::min(p[pair.prior].confidence, c[pair.current].confidence) *
                        (1.0 - pair.cost / (2.0 * options.match_distance_m));
    changes.push_back(change);
  }

  // Unmatched prior objects: removed candidates when covered, else unobserved.
  std::vector<int> views(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (prior_used[i]) continue;
    std::vector<const MapObject*> candidates;  // unmatched current objects that may be this one, moved
    for (std::size_t j = 0; j < c.size(); ++j) {
      if (!current_used[j] && c[j].label == p[i].label && (c[j].centroid - p[i].centroid).norm() <= options.max_move_m) {
        candidates.push_back(&c[j]);
      }
    }
    views[i] = CoveringViews(p[i], current, options, candidates);
    if (views[i] >= options.min_visible_views) continue;
    prior_used[i] = true;
    ObjectChange change;
    change.state = ObjectState::kUnobserved;
    change.label = p[i].label;
    change.prior_id = p[i].id;
    change.before = p[i].centroid;
    change.covering_views = views[i];
    change.confidence = p[i].confidence;
    changes.push_back(change);
  }

  // Moved (paper 003): weighted, min-max normalised physical and appearance distances.
  std::vector<Pair> candidates;
  std::vector<double> physical, appearance, textures;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < c.size(); ++j) {
      if (prior_used[i] || current_used[j] || p[i].label != c[j].label) continue;
      const double distance = (p[i].centroid - c[j].centroid).norm();
      if (distance > options.max_move_m) continue;
      candidates.push_back({static_cast<int>(i), static_cast<int>(j), 0.0});
      physical.push_back(distance);
      const AppearanceTerms terms = CompareAppearance(p[i], c[j]);
      textures.push_back(terms.texture.value_or(0.0));
      appearance.push_back(terms.Distance());
    }
  }
  const auto normalise = [](const std::vector<double>& values, std::size_t k) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    return *hi - *lo > 1e-12 ? (values[k] - *lo) / (*hi - *lo) : 0.0;
  };
  // Paper 003's weighted normalised distance orders the candidates; the gates are absolute (min-max
  // normalised values cannot reject anything: the worst candidate is always 1).
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    candidates[k].cost = options.physical_weight * normalise(physical, k) + options.appearance_weight * normalise(appearance, k);
  }
  std::vector<Pair> gated;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (textures[k] <= options.max_texture_distance) gated.push_back(candidates[k]);
  }
  candidates.swap(gated);
  std::vector<Pair> moved;
  AssignGreedy(candidates, &prior_used, &current_used, &moved);
  for (const Pair& pair : moved) {
    ObjectChange change;
    change.state = ObjectState::kMoved;
    change.label = p[pair.prior].label;
    change.prior_id = p[pair.prior].id, change.current_id = c[pair.current].id;
    change.before = p[pair.prior].centroid, change.after = c[pair.current].centroid;
    change.covering_views = views[pair.prior];
    change.weighted_distance = pair.cost;
    change.rotation = RegisterRotation(p[pair.prior].points, c[pair.current].points);
    change.confidence = std::min(p[pair.prior].confidence, c[pair.current].confidence) * (1.0 - 0.5 * pair.cost);
    changes.push_back(change);
  }

  for (std::size_t i = 0; i < p.size(); ++i) {
    if (prior_used[i]) continue;
    ObjectChange change;
    change.state = ObjectState::kRemoved;
    change.label = p[i].label;
    change.prior_id = p[i].id;
    change.before = p[i].centroid;
    change.covering_views = views[i];
    change.confidence = p[i].confidence * std::min(1.0, views[i] / (2.0 * options.min_visible_views));
    changes.push_back(change);
  }
  for (std::size_t j = 0; j < c.size(); ++j) {
    if (current_used[j]) continue;
    ObjectChange change;
    change.state = ObjectState::kNew;
    change.label = c[j].label;
    change.current_id = c[j].id;
    change.after = c[j].centroid;
    change.confidence = c[j].confidence * std::min(1.0, c[j].detections / 10.0);
    changes.push_back(change);
  }
  return changes;
}

}  // namespace patrolmap::change
