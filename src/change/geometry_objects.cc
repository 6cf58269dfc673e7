#include "patrolmap/change/geometry_objects.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

// The connected component of voxel `seed` among `voxels` (indices into change.changed_voxels), neighbours at most
// `gap` voxels apart along each axis; marks its members in `taken`.
VoxelCluster GrowCluster(const GeometryChange& change, const std::unordered_map<std::uint64_t, std::size_t>& voxels,
                         std::size_t seed, int gap, std::vector<bool>* taken) {
  VoxelCluster cluster;
  std::vector<std::size_t> open = {seed};
  (*taken)[seed] = true;
  double change_sum = 0.0;
  while (!open.empty()) {
    const std::size_t member = open.back();
    open.pop_back();
    const Eigen::Vector3i& index = change.changed_voxels[member];
    cluster.Add(index, change.voxel_size);
    change_sum += std::abs(change.changed_deltas[member]);
    for (int dz = -gap; dz <= gap; ++dz) {
      for (int dy = -gap; dy <= gap; ++dy) {
        for (int dx = -gap; dx <= gap; ++dx) {
          const auto it = voxels.find(VoxelKey(index + Eigen::Vector3i(dx, dy, dz)));
          if (it == voxels.end() || (*taken)[it->second]) continue;
          (*taken)[it->second] = true;
          open.push_back(it->second);
        }
      }
    }
  }
  cluster.mean_change = change_sum / static_cast<double>(cluster.points.size());
  return cluster;
}

bool IsObjectSized(const VoxelCluster& cluster, const GeometryObjectOptions& options) {
  const Eigen::Vector3d extent = cluster.box.sizes();
  return static_cast<int>(cluster.points.size()) >= options.min_voxels &&
         std::max(extent.x(), extent.y()) <= options.max_size_m;
}

// Whether a detected object explains the cluster: its centroid lies in the cluster's box grown by `margin`, or at
// least half of the cluster's voxels lie in the object's box grown by `margin` (stereo often sees a vehicle only by
// its ends, and an end changes apart from the centre).
bool HoldsDetection(const VoxelCluster& cluster, const std::vector<MapObject>& detected, double margin) {
  Eigen::AlignedBox3d grown = cluster.box;
  grown.min().array() -= margin;
  grown.max().array() += margin;
  for (const MapObject& object : detected) {
    if (grown.contains(object.centroid)) return true;
    if (!(object.box_max.array() > object.box_min.array()).all()) continue;  // no extent known
    const Eigen::AlignedBox3d box(object.box_min.array() - margin, object.box_max.array() + margin);
    const auto inside = std::count_if(cluster.points.begin(), cluster.points.end(),
                                      [&box](const Eigen::Vector3f& p) { return box.contains(p.cast<double>()); });
    if (2 * inside >= static_cast<std::ptrdiff_t>(cluster.points.size())) return true;
  }
  return false;
}

// A voxel on a surface for the growth: two returns at least, and this share of the rays that reached it (uncertain
// stereo depth spreads a surface's returns over the voxels before and behind it).
bool IsSurface(const VoxelEvidence& voxel, double min_occupancy) {
  return voxel.hits >= 2 && voxel.hits >= min_occupancy * (voxel.hits + voxel.passes);
}

// The ground's voxel level around `seed` in the patrol's grid (GroundAround, up to the seed's foot); the seed's foot
// less one when no column around it holds a return.
int GroundLevel(const VoxelCluster& seed, const VoxelLookup& grid, double voxel, double search_m) {
  const Eigen::Vector3i low = VoxelIndex(seed.box.min(), voxel), high = VoxelIndex(seed.box.max(), voxel);
  return GroundAround(low, high, voxel, search_m, 0, grid).value_or(low.z() - 1);
}

// Whether no voxel of `cluster` rises more than ground_clearance_voxels above the ground around it: a sheet of
// ground seen a voxel higher or lower in one patrol (what a pose correction leaves), not an object standing there.
bool LiesOnTheGround(const VoxelCluster& cluster, const VoxelLookup& grid, double voxel,
                     const GeometryObjectOptions& options) {
  const int ground = GroundLevel(cluster, grid, voxel, options.ground_search_m);
  return VoxelIndex(cluster.box.max(), voxel).z() <= ground + options.ground_clearance_voxels;
}

// The whole object a seed of changed voxels belongs to, as its patrol's grid holds it (paper 003 projects the
// changed voxels back into the mission's map and segments the object there): the occupied voxels above the
// ground connected to the seed. The seed itself when that grows past max_size_m (a wall, a kerb).
VoxelCluster CompleteObject(const VoxelCluster& seed, const VoxelLookup& grid, double voxel,
                            const GeometryObjectOptions& options) {
  const int ground = GroundLevel(seed, grid, voxel, options.ground_search_m);
  const std::size_t max_voxels = static_cast<std::size_t>(std::pow(options.max_size_m / voxel + 1.0, 2.0) * 4.0);
  VoxelCluster object;
  std::unordered_set<std::uint64_t> seen;
  std::vector<Eigen::Vector3i> open = seed.voxels;
  for (const Eigen::Vector3i& v : open) seen.insert(VoxelKey(v));
  VoxelEvidence evidence;
  while (!open.empty()) {
    const Eigen::Vector3i index = open.back();
    open.pop_back();
    object.Add(index, voxel);
    const Eigen::Vector3d extent = object.box.sizes();
    if (std::max(extent.x(), extent.y()) > options.max_size_m || object.voxels.size() > max_voxels) return seed;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i next = index + Eigen::Vector3i(dx, dy, dz);
          if (next.z() <= ground + options.ground_clearance_voxels || !seen.insert(VoxelKey(next)).second) {
            continue;
          }
          if (grid(next, &evidence) && IsSurface(evidence, options.min_surface_occupancy)) open.push_back(next);
        }
      }
    }
  }
  object.mean_change = seed.mean_change;
  return object;
}

// Adds the voxels of `from` not in `keys` to `into` (and to `keys`); the mean change weighed by the voxels each
// brought.
void Absorb(const VoxelCluster& from, double voxel, std::unordered_set<std::uint64_t>* keys, VoxelCluster* into) {
  const double weight_into = static_cast<double>(into->voxels.size());
  const double weight_from = static_cast<double>(from.voxels.size());
  into->mean_change = (into->mean_change * weight_into + from.mean_change * weight_from) / (weight_into + weight_from);
  for (const Eigen::Vector3i& v : from.voxels) {
    if (keys->insert(VoxelKey(v)).second) into->Add(v, voxel);
  }
}

// Objects whose voxels meet are one (two seeds of one object completed alike); the first keeps the rest.
std::vector<VoxelCluster> MergeSharing(std::vector<VoxelCluster> objects, double voxel) {
  std::unordered_map<std::uint64_t, std::size_t> owner;  // voxel key -> the merged object that has it
  std::unordered_set<std::uint64_t> claimed;             // the voxels of every merged object
  std::vector<VoxelCluster> merged;
  for (VoxelCluster& object : objects) {
    std::size_t into = merged.size();
    for (const Eigen::Vector3i& v : object.voxels) {
      const auto it = owner.find(VoxelKey(v));
      if (it != owner.end()) into = std::min(into, it->second);
    }
    if (into == merged.size()) merged.emplace_back();
    Absorb(object, voxel, &claimed, &merged[into]);
    for (const Eigen::Vector3i& v : object.voxels) owner.emplace(VoxelKey(v), into);
  }
  return merged;
}

// Whether the footprints (horizontal extents of the voxel centres) of two clusters come within `gap` of each other.
bool FootprintsMeet(const VoxelCluster& a, const VoxelCluster& b, double gap) {
  for (int axis = 0; axis < 2; ++axis) {
    if (a.box.max()[axis] + gap < b.box.min()[axis] || b.box.max()[axis] + gap < a.box.min()[axis]) {
      return false;
    }
  }
  return true;
}

// Objects for which `together(a, b)` holds are one, the first taking the others' voxels.
template <typename Together>
std::vector<VoxelCluster> MergeWhere(std::vector<VoxelCluster> objects, double voxel, const Together& together) {
  for (std::size_t a = 0; a < objects.size(); ++a) {
    for (std::size_t b = a + 1; b < objects.size();) {
      if (!together(objects[a], objects[b])) {
        ++b;
        continue;
      }
      std::unordered_set<std::uint64_t> keys;
      for (const Eigen::Vector3i& v : objects[a].voxels) keys.insert(VoxelKey(v));
      Absorb(objects[b], voxel, &keys, &objects[a]);
      objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(b));
      b = a + 1;  // the grown object may now join one passed over
    }
  }
  return objects;
}

std::vector<VoxelCluster> ObjectClusters(const GeometryChange& change, bool appeared, const VoxelLookup& grid,
                                         const std::vector<MapObject>& detected, const GeometryObjectOptions& options) {
  std::vector<VoxelCluster> seeds;
  for (VoxelCluster& cluster : ClusterChangedVoxels(change, appeared, options.cluster_gap_voxels)) {
    if (!IsObjectSized(cluster, options)) continue;
    if (grid && options.drop_ground_sheets && LiesOnTheGround(cluster, grid, change.voxel_size, options)) continue;
    seeds.push_back(grid && options.complete_objects ? CompleteObject(cluster, grid, change.voxel_size, options)
                                                     : std::move(cluster));
  }
  std::vector<VoxelCluster> clusters;
  std::vector<VoxelCluster> objects = MergeSharing(std::move(seeds), change.voxel_size);
  // Footprints that meet: objects stand on the ground (a side seen apart from the top, two faces the grid does not
  // connect).
  objects = MergeWhere(std::move(objects), change.voxel_size, [&options](const VoxelCluster& a, const VoxelCluster& b) {
    return FootprintsMeet(a, b, options.footprint_gap_m + 1e-6);
  });
  for (VoxelCluster& cluster : objects) {
    if (IsObjectSized(cluster, options) && !HoldsDetection(cluster, detected, options.detection_margin_m)) {
      clusters.push_back(std::move(cluster));
    }
  }
  return clusters;
}

// Two clusters, their centroids and their points indexed for the shape test of a move.
struct ShapePair {
  ShapePair(const VoxelCluster& b, const VoxelCluster& a, const Eigen::Vector3d& b_centroid,
            const Eigen::Vector3d& a_centroid)
      : before(b),
        after(a),
        before_centroid(b_centroid),
        after_centroid(a_centroid),
        before_index(b.points),
        after_index(a.points) {}
  const VoxelCluster& before;
  const VoxelCluster& after;
  const Eigen::Vector3d before_centroid, after_centroid;
  const PointIndex before_index, after_index;
};

// The smaller of the two shares of voxels that lie within `tolerance` of the other cluster once moved onto it by
// `rotation` (before -> after) about the centroids, the after centroid shifted horizontally by up to `search` each
// way in steps of `step`: the best shift. A partial view pulls a centroid off the object's centre.
double ShapeOverlap(const ShapePair& pair, const Eigen::Matrix3d& rotation, double tolerance, double search,
                    double step) {
  const std::vector<Eigen::Vector3f>&before = pair.before.points, &after = pair.after.points;
  const Eigen::Vector3d& from = pair.before_centroid;
  std::vector<Eigen::Vector3f> forward(before.size()), backward(after.size());  // reused for every shift
  const int steps = static_cast<int>(std::floor(search / step + 1e-9));
  double best = 0.0;
  for (int i = -steps; i <= steps; ++i) {
    for (int j = -steps; j <= steps; ++j) {
      const Eigen::Vector3d to = pair.after_centroid + Eigen::Vector3d(i * step, j * step, 0.0);
      for (std::size_t k = 0; k < before.size(); ++k) {
        forward[k] = (rotation * (before[k].cast<double>() - from) + to).cast<float>();
      }
      for (std::size_t k = 0; k < after.size(); ++k) {
        backward[k] = (rotation.transpose() * (after[k].cast<double>() - to) + from).cast<float>();
      }
      best = std::max(best, std::min(pair.after_index.PairFraction(forward, tolerance),
                                     pair.before_index.PairFraction(backward, tolerance)));
    }
  }
  return best;
}

struct MoveCandidate {
  std::size_t vanished, appeared;
  double cost, overlap;
  Eigen::Matrix3d rotation;
};

// Paper 003's weighted distance of a move `distance_m` long between shapes overlapping by `overlap`.
double MoveCost(double distance_m, double overlap, const GeometryObjectOptions& options) {
  const double normalised = options.max_move_m > 0.0 ? distance_m / options.max_move_m : 0.0;
  return options.physical_weight * normalised + (1.0 - options.physical_weight) * (1.0 - overlap);
}

// Whether appeared cluster `after` may be vanished cluster `before` moved; fills the candidate's cost. The shape
// test searches shifts in steps of `voxel`, or of half the shape tolerance where that is larger (a finer shift
// changes little within the tolerance, and a coarser step bounds the search).
bool MayHaveMoved(const VoxelCluster& before, const VoxelCluster& after, double voxel,
                  const GeometryObjectOptions& options, MoveCandidate* candidate) {
  const Eigen::Vector3d before_centroid = before.Centroid(), after_centroid = after.Centroid();
  const Eigen::Vector3d shift = after_centroid - before_centroid;
  const double distance = shift.head<2>().norm();
  if (distance > options.max_move_m) return false;
  if (std::abs(after.box.max().z() - before.box.max().z()) > options.max_top_difference_m) return false;
  // The registration of partial surfaces can flip an axis: keep it only where it fits better than none.
  const Eigen::Matrix3d registered = RegisterRotation(before.points, after.points);
  const ShapePair pair(before, after, before_centroid, after_centroid);
  const double step = std::max(voxel, options.shape_tolerance_m / 2);
  const double unrotated =
      ShapeOverlap(pair, Eigen::Matrix3d::Identity(), options.shape_tolerance_m, options.shape_search_m, step);
  const double rotated = ShapeOverlap(pair, registered, options.shape_tolerance_m, options.shape_search_m, step);
  candidate->overlap = std::max(unrotated, rotated);
  candidate->rotation = rotated > unrotated ? registered : Eigen::Matrix3d::Identity();
  if (candidate->overlap < options.min_shape_overlap) return false;
  candidate->cost = MoveCost(distance, candidate->overlap, options);
  return true;
}

// Paper 003's greedy assignment: the candidate pairs (each with `vanished`, `appeared` and `cost`) cheapest first,
// each cluster taken at most once; the taken ones are marked in `vanished_used` and `appeared_used`.
template <typename Candidate>
std::vector<Candidate> TakeCheapest(std::vector<Candidate> candidates, std::vector<bool>* vanished_used,
                                    std::vector<bool>* appeared_used) {
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
  std::vector<Candidate> chosen;
  for (const Candidate& candidate : candidates) {
    if ((*vanished_used)[candidate.vanished] || (*appeared_used)[candidate.appeared]) continue;
    (*vanished_used)[candidate.vanished] = (*appeared_used)[candidate.appeared] = true;
    chosen.push_back(candidate);
  }
  return chosen;
}

// The moves between vanished and appeared clusters (MayHaveMoved), greedily by cost; marks the clusters taken.
std::vector<MoveCandidate> PairMoves(const std::vector<VoxelCluster>& vanished,
                                     const std::vector<VoxelCluster>& appeared, double voxel,
                                     const GeometryObjectOptions& options, std::vector<bool>* vanished_used,
                                     std::vector<bool>* appeared_used) {
  std::vector<MoveCandidate> candidates;
  for (std::size_t v = 0; v < vanished.size(); ++v) {
    for (std::size_t a = 0; a < appeared.size(); ++a) {
      MoveCandidate candidate{v, a, 0.0, 0.0, Eigen::Matrix3d::Identity()};
      if (MayHaveMoved(vanished[v], appeared[a], voxel, options, &candidate)) candidates.push_back(candidate);
    }
  }
  return TakeCheapest(std::move(candidates), vanished_used, appeared_used);
}

ObjectChange ClassAgnostic(ObjectState state, const VoxelCluster* before, const VoxelCluster* after) {
  ObjectChange change;
  change.state = state;
  change.label = kClassAgnosticLabel;
  change.class_agnostic = true;
  double confidence = 0.0;
  int sides = 0;
  if (before != nullptr) {
    change.before = before->Position();
    change.box_before = before->box;
    confidence += before->mean_change, ++sides;
  }
  if (after != nullptr) {
    change.after = after->Position();
    change.box_after = after->box;
    confidence += after->mean_change, ++sides;
  }
  change.confidence = std::clamp(confidence / std::max(1, sides), 0.0, 1.0);
  return change;
}

// A class-agnostic move, its confidence weighed by the shapes' overlap, with paper 003's weighted distance.
ObjectChange Moved(const VoxelCluster& before, const VoxelCluster& after, double overlap, double cost) {
  ObjectChange moved = ClassAgnostic(ObjectState::kMoved, &before, &after);
  moved.confidence *= overlap;
  moved.weighted_distance = cost;
  return moved;
}

}  // namespace

Eigen::Vector3d VoxelCluster::Centroid() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return points.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(points.size()));
}

void VoxelCluster::Add(const Eigen::Vector3i& index, double voxel_size) {
  const Eigen::Vector3d centre = index.cast<double>() * voxel_size;
  voxels.push_back(index);
  points.push_back(centre.cast<float>());
  box.extend(centre);
}

Eigen::Vector3d VoxelCluster::Position() const {
  if (points.empty()) return Eigen::Vector3d::Zero();
  return box.center();
}

std::vector<VoxelCluster> ClusterChangedVoxels(const GeometryChange& change, bool appeared, int gap_voxels) {
  std::unordered_map<std::uint64_t, std::size_t> voxels;
  for (std::size_t i = 0; i < change.changed_voxels.size() && i < change.changed_deltas.size(); ++i) {
    if ((change.changed_deltas[i] > 0.0f) == appeared) voxels.emplace(VoxelKey(change.changed_voxels[i]), i);
  }
  std::vector<bool> taken(change.changed_voxels.size(), false);
  std::vector<VoxelCluster> clusters;
  for (std::size_t i = 0; i < change.changed_voxels.size() && i < change.changed_deltas.size(); ++i) {
    if (taken[i] || (change.changed_deltas[i] > 0.0f) != appeared) continue;
    clusters.push_back(GrowCluster(change, voxels, i, gap_voxels, &taken));
  }
  return clusters;
}

std::vector<ObjectChange> GeometryObjects(const GeometryChange& change, const VoxelLookup& prior_grid,
                                          const VoxelLookup& current_grid, const std::vector<MapObject>& prior_detected,
                                          const std::vector<MapObject>& current_detected,
                                          const GeometryObjectOptions& options) {
  std::vector<ObjectChange> objects;
  if (!options.enabled) return objects;
  const std::vector<VoxelCluster> vanished = ObjectClusters(change, false, prior_grid, prior_detected, options);
  const std::vector<VoxelCluster> appeared = ObjectClusters(change, true, current_grid, current_detected, options);
  std::vector<bool> vanished_moved(vanished.size()), appeared_moved(appeared.size());
  for (const MoveCandidate& move :
       PairMoves(vanished, appeared, change.voxel_size, options, &vanished_moved, &appeared_moved)) {
    ObjectChange moved = Moved(vanished[move.vanished], appeared[move.appeared], move.overlap, move.cost);
    moved.rotation = move.rotation;
    objects.push_back(std::move(moved));
  }
  for (std::size_t v = 0; v < vanished.size(); ++v) {
    if (!vanished_moved[v]) objects.push_back(ClassAgnostic(ObjectState::kRemoved, &vanished[v], nullptr));
  }
  for (std::size_t a = 0; a < appeared.size(); ++a) {
    if (!appeared_moved[a]) objects.push_back(ClassAgnostic(ObjectState::kNew, nullptr, &appeared[a]));
  }
  return objects;
}

}  // namespace patrolmap::change
