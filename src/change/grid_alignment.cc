#include "patrolmap/change/grid_alignment.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_set>
#include <vector>

#include "patrolmap/change/evidence_grid.h"

namespace patrolmap::change {
namespace {

constexpr int kCoarse = 4;  // voxels per coarse cell along each axis

int FloorDiv(int value, int by) { return value >= 0 ? value / by : -((-value + by - 1) / by); }

std::vector<Eigen::Vector3i> OccupiedVoxels(const EvidenceGridData& grid) {
  std::vector<Eigen::Vector3i> occupied;
  for (const VoxelEvidence& v : grid.voxels) {
    if (IsOccupied(&v)) occupied.emplace_back(v.x, v.y, v.z);
  }
  return occupied;
}

std::vector<Eigen::Vector3i> Coarse(const std::vector<Eigen::Vector3i>& voxels) {
  std::unordered_set<std::uint64_t> seen;
  std::vector<Eigen::Vector3i> cells;
  for (const Eigen::Vector3i& v : voxels) {
    const Eigen::Vector3i cell(FloorDiv(v.x(), kCoarse), FloorDiv(v.y(), kCoarse), FloorDiv(v.z(), kCoarse));
    if (seen.insert(VoxelKey(cell)).second) cells.push_back(cell);
  }
  return cells;
}

std::unordered_set<std::uint64_t> KeySet(const std::vector<Eigen::Vector3i>& voxels) {
  std::unordered_set<std::uint64_t> keys;
  keys.reserve(voxels.size());
  for (const Eigen::Vector3i& v : voxels) keys.insert(VoxelKey(v));
  return keys;
}

long long Overlap(const std::vector<Eigen::Vector3i>& current, const std::unordered_set<std::uint64_t>& prior,
                  const Eigen::Vector3i& shift) {
  long long count = 0;
  for (const Eigen::Vector3i& v : current) count += prior.count(VoxelKey(v + shift));
  return count;
}

// The shift within ±reach of `centre` (each axis) with the largest overlap; the nearest to `centre` on ties.
Eigen::Vector3i BestShift(const std::vector<Eigen::Vector3i>& current, const std::unordered_set<std::uint64_t>& prior,
                          const Eigen::Vector3i& centre, int reach, long long* best_overlap) {
  Eigen::Vector3i best = centre;
  *best_overlap = Overlap(current, prior, centre);
  for (int dx = -reach; dx <= reach; ++dx) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dz = -reach; dz <= reach; ++dz) {
        const Eigen::Vector3i shift = centre + Eigen::Vector3i(dx, dy, dz);
        const long long overlap = Overlap(current, prior, shift);
        if (overlap > *best_overlap) *best_overlap = overlap, best = shift;
      }
    }
  }
  return best;
}

}  // namespace

ShiftSearch::ShiftSearch(const EvidenceGridData& prior, const GridAlignmentOptions& options)
    : voxel_size_(prior.voxel_size), options_(options) {
  if (voxel_size_ <= 0.0 || options_.max_shift_m <= 0.0) return;
  const std::vector<Eigen::Vector3i> occupied = OccupiedVoxels(prior);
  fine_ = KeySet(occupied);
  coarse_ = KeySet(Coarse(occupied));
}

GridShift ShiftSearch::Find(const EvidenceGridData& current) const {
  return current.voxel_size == voxel_size_ ? Find(OccupiedVoxels(current)) : GridShift();
}

GridShift ShiftSearch::Find(const EvidenceGrid& current) const {
  return current.voxel_size() == voxel_size_ ? Find(current.OccupiedVoxels()) : GridShift();
}

GridShift ShiftSearch::Find(const std::vector<Eigen::Vector3i>& after) const {
  GridShift result;
  if (fine_.empty() || after.empty()) return result;
  result.overlap_unshifted = Overlap(after, fine_, Eigen::Vector3i::Zero());
  const int reach = static_cast<int>(std::ceil(options_.max_shift_m / voxel_size_));
  long long coarse_overlap = 0;
  const Eigen::Vector3i coarse =
      BestShift(Coarse(after), coarse_, Eigen::Vector3i::Zero(), (reach + kCoarse - 1) / kCoarse, &coarse_overlap);
  Eigen::Vector3i fine = BestShift(after, fine_, coarse * kCoarse, kCoarse, &result.overlap);
  if (fine.cwiseAbs().maxCoeff() > reach) fine = Eigen::Vector3i::Zero(), result.overlap = result.overlap_unshifted;
  result.voxels = result.best = fine;
  result.best_overlap = result.overlap;
  result.applied =
      fine != Eigen::Vector3i::Zero() &&
      static_cast<double>(result.overlap) > (1.0 + options_.min_gain) * static_cast<double>(result.overlap_unshifted);
  if (!result.applied) result.voxels = Eigen::Vector3i::Zero(), result.overlap = result.overlap_unshifted;
  return result;
}

GridShift FindGridShift(const EvidenceGridData& prior, const EvidenceGridData& current,
                        const GridAlignmentOptions& options) {
  return ShiftSearch(prior, options).Find(current);
}

GridShift FindGridShift(const EvidenceGridData& prior, const EvidenceGrid& current,
                        const GridAlignmentOptions& options) {
  return ShiftSearch(prior, options).Find(current);
}

std::string DescribeShift(const GridShift& shift, double voxel_size, const std::string& reference) {
  const Eigen::Vector3d m = shift.voxels.cast<double>() * voxel_size;
  char text[160];
  std::snprintf(text, sizeof(text),
                "moved by (%.2f, %.2f, %.2f) m onto %s's surfaces: %lld of its occupied voxels meet ", m.x(), m.y(),
                m.z(), reference.c_str(), shift.overlap);
  return text + reference + "'s, " + std::to_string(shift.overlap_unshifted) + " before";
}

void ShiftRecord(const Eigen::Vector3i& shift_voxels, PatrolRecord* record) {
  const double size = record->grid.voxel_size;
  for (VoxelEvidence& v : record->grid.voxels) {  // a translation keeps the (x, y, z) order
    v.x += shift_voxels.x(), v.y += shift_voxels.y(), v.z += shift_voxels.z();
  }
  MoveRecordPoses(shift_voxels.cast<double>() * size, record);
}

void MoveRecordPoses(const Eigen::Vector3d& shift, PatrolRecord* record) {
  const Eigen::Vector3f shift_f = shift.cast<float>();
  for (MapObject& object : record->objects) {
    object.centroid += shift, object.box_min += shift, object.box_max += shift;
    for (Eigen::Vector3f& point : object.points) point += shift_f;
  }
  for (CameraPoseSample& view : record->views) view.position += shift;
  for (RouteFrame& frame : record->route) {
    if (frame.pose) frame.pose->position += shift;
  }
}

}  // namespace patrolmap::change
