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

// A voxel rays passed (at least separating_rays) that holds no surface.
bool SeenFree(const VoxelEvidence& voxel, const GeometryObjectOptions& options) {
  return voxel.hits + voxel.passes >= options.separating_rays && !IsSurface(voxel, options.min_surface_occupancy);
}

// Whether the patrol's grid shows free space between two objects: a voxel on the straight line between their
// centroids, in neither of them, that rays passed (at least `separating_rays`) and that holds no surface. A vehicle
// seen by stereo only at its ends (its flat sides give no match) has no ray inside it: unseen, not free.
bool SeenApart(const VoxelCluster& a, const VoxelCluster& b, const VoxelLookup& grid, double voxel,
               const GeometryObjectOptions& options) {
  std::unordered_set<std::uint64_t> members;
  for (const Eigen::Vector3i& v : a.voxels) members.insert(VoxelKey(v));
  for (const Eigen::Vector3i& v : b.voxels) members.insert(VoxelKey(v));
  const Eigen::Vector3d from = a.Centroid(), to = b.Centroid();
  const int steps = static_cast<int>(std::ceil((to - from).norm() / (voxel / 2)));
  VoxelEvidence evidence;
  for (int i = 1; i < steps; ++i) {
    const Eigen::Vector3i index = VoxelIndex(from + (to - from) * (static_cast<double>(i) / steps), voxel);
    if (members.count(VoxelKey(index)) > 0 || !grid(index, &evidence)) continue;
    if (SeenFree(evidence, options)) return true;
  }
  return false;
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
  // Near, and no free space seen between them: the ends of a vehicle whose sides and top stereo does not see.
  if (grid && options.unseen_join_m > 0.0) {
    objects = MergeWhere(std::move(objects), change.voxel_size, [&](const VoxelCluster& a, const VoxelCluster& b) {
      return FootprintsMeet(a, b, options.unseen_join_m) && !SeenApart(a, b, grid, change.voxel_size, options);
    });
  }
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
  const double top_difference = std::abs(after.box.max().z() - before.box.max().z());
  if (top_difference > std::max(options.max_top_difference_m, options.alike_top_difference_m)) return false;
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
  // A top a voxel apart only for shapes that agree closely (the top of a crate whose lid lies on a voxel boundary).
  if (top_difference > options.max_top_difference_m && candidate->overlap < options.alike_shape_overlap) return false;
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

// The voxel keys of `cluster` and of every voxel within `reach` voxels of one of them.
std::unordered_set<std::uint64_t> Dilated(const VoxelCluster& cluster, int reach) {
  std::unordered_set<std::uint64_t> keys;
  for (const Eigen::Vector3i& v : cluster.voxels) {
    for (int dz = -reach; dz <= reach; ++dz) {
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) keys.insert(VoxelKey(v + Eigen::Vector3i(dx, dy, dz)));
      }
    }
  }
  return keys;
}

// Whether `grid` holds a surface within `reach` voxels of `index` at its height (a moved object keeps its height;
// the ground below it is no surface it left).
bool SurfaceNear(const Eigen::Vector3i& index, int reach, const VoxelLookup& grid, double min_occupancy) {
  VoxelEvidence evidence;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      if (grid(index + Eigen::Vector3i(dx, dy, 0), &evidence) && IsSurface(evidence, min_occupancy)) return true;
    }
  }
  return false;
}

// One object seen whole in one patrol and only by the part of it that changed in the other: an object moved less
// than its own length, whose other part lies where the object stands in the other patrol, unchanged to the grids.
struct PartialMove {
  std::size_t vanished = 0, appeared = 0;
  bool appeared_whole = false;                      // the whole object is the appeared one (else the vanished one)
  Eigen::Vector3i shift = Eigen::Vector3i::Zero();  // [voxels] the whole, shifted by this, stands where it was (is)
  double cost = 0.0, overlap = 0.0;
};

// The grids of a whole object's patrol (`own`) and of the other patrol (`other`), where its part changed.
struct GridPair {
  const VoxelLookup& own;
  const VoxelLookup& other;
};

// Where a whole object, shifted, lands in the other patrol's grid: shares of its voxels.
struct Landing {
  double on_left_surface = 0.0;  // on surfaces the other grid holds (within `reach` voxels) and its own grid does not
                                 // hold outside the whole: the place it left or took, not structure both patrols saw
  double on_free_space = 0.0;    // where the other grid saw free space and no surface within reach: it did not stand
                                 // there
  double on_left_voxel = 0.0;    // as on_left_surface, on such a surface voxel itself (how exactly it lands)
};

Landing LandShifted(const VoxelCluster& whole, const Eigen::Vector3i& shift,
                    const std::unordered_set<std::uint64_t>& own_reach, const GridPair& grids, int reach,
                    const GeometryObjectOptions& options) {
  int landed = 0, free = 0, exact = 0;
  VoxelEvidence evidence;
  for (const Eigen::Vector3i& v : whole.voxels) {
    const Eigen::Vector3i there = v + shift;
    if (!SurfaceNear(there, reach, grids.other, options.min_surface_occupancy)) {
      free += grids.other(there, &evidence) && SeenFree(evidence, options);
      continue;
    }
    const bool still_there = own_reach.count(VoxelKey(there)) == 0 && grids.own(there, &evidence) &&
                             IsSurface(evidence, options.min_surface_occupancy);
    if (still_there) continue;
    ++landed;
    exact += SurfaceNear(there, 0, grids.other, options.min_surface_occupancy);
  }
  Landing landing;
  if (whole.voxels.empty()) return landing;
  const double voxels = static_cast<double>(whole.voxels.size());
  landing.on_left_surface = landed / voxels;
  landing.on_free_space = free / voxels;
  landing.on_left_voxel = exact / voxels;
  return landing;
}

// Whether at least `share` of `part` lies outside the footprint of `whole` (the box of its voxel centres).
bool MostlyOutside(const VoxelCluster& part, const VoxelCluster& whole, double share) {
  const Eigen::AlignedBox3d& box = whole.box;
  const auto outside = std::count_if(part.points.begin(), part.points.end(), [&box](const Eigen::Vector3f& p) {
    return p.x() < box.min().x() || p.x() > box.max().x() || p.y() < box.min().y() || p.y() > box.max().y();
  });
  return static_cast<double>(outside) >= share * static_cast<double>(part.points.size());
}

// Whether shifting `whole` by (i, j) voxels may make it the other side of a move of which `part` is the changed end:
// farther than shape_search_m and at most max_move_m, less than the whole's own extent along each axis (where it
// was and where it is overlap) and farther than the part reaches along the shift (the part is the ground the object
// left or took, not a whole object standing in its place).
bool PartialShiftAllowed(int i, int j, const VoxelCluster& whole, const VoxelCluster& part, double voxel,
                         const GeometryObjectOptions& options) {
  const double distance = voxel * std::hypot(i, j);
  if (distance <= options.shape_search_m || distance > options.max_move_m) return false;
  const Eigen::Vector3d size = whole.box.sizes(), part_size = part.box.sizes();
  if (std::abs(i) * voxel >= size.x() || std::abs(j) * voxel >= size.y()) return false;
  return std::abs(i) * part_size.x() + std::abs(j) * part_size.y() < voxel * (i * i + j * j);
}

// The best horizontal shift (in voxels; PartialShiftAllowed) that moves `whole` onto `part`, the part mostly outside
// the whole's footprint: at least min_shape_overlap of the part within shape_tolerance_m of the shifted whole, and
// as much of the shifted whole landing on surfaces it left, at most max_partial_free_share on free space
// (LandShifted). False when none qualifies; `overlap` is the smaller of the two shares at the best shift.
bool ShiftOntoPart(const VoxelCluster& whole, const VoxelCluster& part, const GridPair& grids, double voxel,
                   const GeometryObjectOptions& options, Eigen::Vector3i* best_shift, double* overlap) {
  *overlap = 0.0;
  if (!MostlyOutside(part, whole, options.min_shape_overlap)) return false;
  const int reach = static_cast<int>(std::floor(options.shape_tolerance_m / voxel + 1e-9));
  const PointIndex index(whole.points);
  const std::unordered_set<std::uint64_t> own_reach = Dilated(whole, reach);
  std::vector<Eigen::Vector3f> moved_part(part.points.size());
  double best_exact = 0.0;
  // Shifts that bring the whole's box within reach of the part's.
  Eigen::Vector2i low, high;
  for (int axis = 0; axis < 2; ++axis) {
    low[axis] = static_cast<int>(std::floor((part.box.min()[axis] - whole.box.max()[axis]) / voxel)) - reach;
    high[axis] = static_cast<int>(std::ceil((part.box.max()[axis] - whole.box.min()[axis]) / voxel)) + reach;
  }
  for (int i = low.x(); i <= high.x(); ++i) {
    for (int j = low.y(); j <= high.y(); ++j) {
      if (!PartialShiftAllowed(i, j, whole, part, voxel, options)) continue;
      const Eigen::Vector3f offset(static_cast<float>(i * voxel), static_cast<float>(j * voxel), 0.0f);
      for (std::size_t k = 0; k < part.points.size(); ++k) moved_part[k] = part.points[k] - offset;
      const double covered = index.PairFraction(moved_part, options.shape_tolerance_m);
      if (covered < options.min_shape_overlap || covered < *overlap) continue;
      const Eigen::Vector3i shift(i, j, 0);
      const Landing landing = LandShifted(whole, shift, own_reach, grids, reach, options);
      const double landed = landing.on_left_surface;
      if (landed < options.min_shape_overlap || landing.on_free_space > options.max_partial_free_share ||
          std::min(covered, landed) < *overlap) {
        continue;
      }
      // Shifts a voxel apart often tie within the tolerance: the one landing more exactly on the surfaces wins.
      if (std::min(covered, landed) == *overlap && landing.on_left_voxel <= best_exact) continue;
      *overlap = std::min(covered, landed);
      *best_shift = shift;
      best_exact = landing.on_left_voxel;
    }
  }
  return *overlap > 0.0;
}

// Pairs the vanished and appeared objects no move took, where one is whole and the other the part of it that changed
// (ShiftOntoPart, either way round), greedily by paper 003's weighted distance.
std::vector<PartialMove> PairPartialMoves(const std::vector<VoxelCluster>& vanished,
                                          const std::vector<VoxelCluster>& appeared, std::vector<bool>* vanished_used,
                                          std::vector<bool>* appeared_used, const VoxelLookup& prior_grid,
                                          const VoxelLookup& current_grid, double voxel,
                                          const GeometryObjectOptions& options) {
  std::vector<PartialMove> candidates;
  for (std::size_t v = 0; v < vanished.size(); ++v) {
    for (std::size_t a = 0; a < appeared.size(); ++a) {
      if ((*vanished_used)[v] || (*appeared_used)[a]) continue;
      // No shift of at most max_move_m brings objects of at most max_size_m together from farther.
      const double apart = (vanished[v].Position() - appeared[a].Position()).head<2>().norm();
      if (apart > options.max_move_m + options.max_size_m) continue;
      for (const bool appeared_whole : {true, false}) {
        const VoxelCluster& whole = appeared_whole ? appeared[a] : vanished[v];
        const VoxelCluster& part = appeared_whole ? vanished[v] : appeared[a];
        const GridPair grids{appeared_whole ? current_grid : prior_grid, appeared_whole ? prior_grid : current_grid};
        PartialMove move;
        move.vanished = v, move.appeared = a, move.appeared_whole = appeared_whole;
        if (!ShiftOntoPart(whole, part, grids, voxel, options, &move.shift, &move.overlap)) continue;
        move.cost = MoveCost(voxel * move.shift.cast<double>().norm(), move.overlap, options);
        candidates.push_back(move);
      }
    }
  }
  return TakeCheapest(std::move(candidates), vanished_used, appeared_used);
}

// `cluster` shifted by `shift` voxels.
VoxelCluster Shifted(const VoxelCluster& cluster, const Eigen::Vector3i& shift, double voxel) {
  VoxelCluster shifted;
  for (const Eigen::Vector3i& v : cluster.voxels) shifted.Add(v + shift, voxel);
  shifted.mean_change = cluster.mean_change;
  return shifted;
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
  if (options.partial_moves && prior_grid && current_grid) {
    for (const PartialMove& move : PairPartialMoves(vanished, appeared, &vanished_moved, &appeared_moved, prior_grid,
                                                    current_grid, change.voxel_size, options)) {
      const VoxelCluster& whole = move.appeared_whole ? appeared[move.appeared] : vanished[move.vanished];
      const VoxelCluster other_place = Shifted(whole, move.shift, change.voxel_size);
      objects.push_back(move.appeared_whole ? Moved(other_place, whole, move.overlap, move.cost)
                                            : Moved(whole, other_place, move.overlap, move.cost));
    }
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
