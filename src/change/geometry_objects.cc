#include "patrolmap/change/geometry_objects.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

std::uint64_t VoxelKey(const Eigen::Vector3i& v) {
  const auto part = [](int value) { return static_cast<std::uint64_t>(value + (1 << 20)) & 0x1fffff; };
  return part(v.x()) << 42 | part(v.y()) << 21 | part(v.z());
}

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
    const Eigen::Vector3d centre = index.cast<double>() * change.voxel_size;
    cluster.points.push_back(centre.cast<float>());
    cluster.box.extend(centre);
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

// Whether a detected object's centroid lies in the cluster's box grown by `margin`.
bool HoldsDetection(const VoxelCluster& cluster, const std::vector<MapObject>& detected, double margin) {
  Eigen::AlignedBox3d grown = cluster.box;
  grown.min().array() -= margin;
  grown.max().array() += margin;
  return std::any_of(detected.begin(), detected.end(),
                     [&grown](const MapObject& object) { return grown.contains(object.centroid); });
}

std::vector<VoxelCluster> ObjectClusters(const GeometryChange& change, bool appeared,
                                         const std::vector<MapObject>& detected, const GeometryObjectOptions& options) {
  std::vector<VoxelCluster> clusters;
  for (VoxelCluster& cluster : ClusterChangedVoxels(change, appeared, options.cluster_gap_voxels)) {
    if (IsObjectSized(cluster, options) && !HoldsDetection(cluster, detected, options.detection_margin_m)) {
      clusters.push_back(std::move(cluster));
    }
  }
  return clusters;
}

// `points` rotated by `rotation` about `from` and moved to `to`.
std::vector<Eigen::Vector3f> Moved(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3d& rotation,
                                   const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  std::vector<Eigen::Vector3f> moved;
  moved.reserve(points.size());
  for (const Eigen::Vector3f& p : points) moved.push_back((rotation * (p.cast<double>() - from) + to).cast<float>());
  return moved;
}

// The smaller of the two shares of voxels that lie on the other cluster once moved onto it by `rotation`
// (before -> after) about the centroids.
double ShapeOverlap(const VoxelCluster& before, const VoxelCluster& after, const Eigen::Matrix3d& rotation,
                    double tolerance) {
  const Eigen::Vector3d b = before.Centroid(), a = after.Centroid();
  const double forward = PairFraction(Moved(before.points, rotation, b, a), after.points, tolerance);
  const double backward = PairFraction(Moved(after.points, rotation.transpose(), a, b), before.points, tolerance);
  return std::min(forward, backward);
}

struct MoveCandidate {
  std::size_t vanished, appeared;
  double cost, overlap;
  Eigen::Matrix3d rotation;
};

// Whether appeared cluster `after` may be vanished cluster `before` moved; fills the candidate's cost.
bool MayHaveMoved(const VoxelCluster& before, const VoxelCluster& after, const GeometryObjectOptions& options,
                  MoveCandidate* candidate) {
  const Eigen::Vector3d shift = after.Centroid() - before.Centroid();
  const double distance = shift.head<2>().norm();
  if (distance > options.max_move_m) return false;
  if (std::abs(after.box.max().z() - before.box.max().z()) > options.max_top_difference_m) return false;
  // The registration of partial surfaces can flip an axis: keep it only where it fits better than none.
  const Eigen::Matrix3d registered = RegisterRotation(before.points, after.points);
  const double unrotated = ShapeOverlap(before, after, Eigen::Matrix3d::Identity(), options.shape_tolerance_m);
  const double rotated = ShapeOverlap(before, after, registered, options.shape_tolerance_m);
  candidate->overlap = std::max(unrotated, rotated);
  candidate->rotation = rotated > unrotated ? registered : Eigen::Matrix3d::Identity();
  if (candidate->overlap < options.min_shape_overlap) return false;
  const double normalised = options.max_move_m > 0.0 ? distance / options.max_move_m : 0.0;
  candidate->cost = options.physical_weight * normalised + options.shape_weight * (1.0 - candidate->overlap);
  return true;
}

std::vector<MoveCandidate> PairMoves(const std::vector<VoxelCluster>& vanished,
                                     const std::vector<VoxelCluster>& appeared, const GeometryObjectOptions& options) {
  std::vector<MoveCandidate> candidates;
  for (std::size_t v = 0; v < vanished.size(); ++v) {
    for (std::size_t a = 0; a < appeared.size(); ++a) {
      MoveCandidate candidate{v, a, 0.0, 0.0, Eigen::Matrix3d::Identity()};
      if (MayHaveMoved(vanished[v], appeared[a], options, &candidate)) candidates.push_back(candidate);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const MoveCandidate& x, const MoveCandidate& y) { return x.cost < y.cost; });
  std::vector<bool> vanished_used(vanished.size()), appeared_used(appeared.size());
  std::vector<MoveCandidate> chosen;
  for (const MoveCandidate& candidate : candidates) {
    if (vanished_used[candidate.vanished] || appeared_used[candidate.appeared]) continue;
    vanished_used[candidate.vanished] = appeared_used[candidate.appeared] = true;
    chosen.push_back(candidate);
  }
  return chosen;
}

ObjectChange ClassAgnostic(ObjectState state, const VoxelCluster* before, const VoxelCluster* after) {
  ObjectChange change;
  change.state = state;
  change.label = kClassAgnosticLabel;
  change.class_agnostic = true;
  double confidence = 0.0;
  int sides = 0;
  if (before != nullptr) {
    change.before = before->Centroid();
    change.box_before = before->box;
    confidence += before->mean_change, ++sides;
  }
  if (after != nullptr) {
    change.after = after->Centroid();
    change.box_after = after->box;
    confidence += after->mean_change, ++sides;
  }
  change.confidence = std::clamp(confidence / std::max(1, sides), 0.0, 1.0);
  return change;
}

}  // namespace

Eigen::Vector3d VoxelCluster::Centroid() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return points.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(points.size()));
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

std::vector<ObjectChange> GeometryObjects(const GeometryChange& change, const std::vector<MapObject>& prior_detected,
                                          const std::vector<MapObject>& current_detected,
                                          const GeometryObjectOptions& options) {
  std::vector<ObjectChange> objects;
  if (!options.enabled) return objects;
  const std::vector<VoxelCluster> vanished = ObjectClusters(change, false, prior_detected, options);
  const std::vector<VoxelCluster> appeared = ObjectClusters(change, true, current_detected, options);
  std::vector<bool> vanished_moved(vanished.size()), appeared_moved(appeared.size());
  for (const MoveCandidate& move : PairMoves(vanished, appeared, options)) {
    ObjectChange moved = ClassAgnostic(ObjectState::kMoved, &vanished[move.vanished], &appeared[move.appeared]);
    moved.confidence *= move.overlap;
    moved.rotation = move.rotation;
    moved.weighted_distance = move.cost;
    objects.push_back(std::move(moved));
    vanished_moved[move.vanished] = appeared_moved[move.appeared] = true;
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
