// Aligns a new patrol to the map's earlier one before they are compared: the whole-voxel shift that puts the
// most of its occupied voxels onto occupied voxels of the earlier patrol's grid (paper 003 registers missions
// onto each other before it looks for changes). A shift common to the whole flight (the day's GNSS bias, a pose
// source's other origin) moves every surface and would make everything differ; changes move a few voxels only.
// Searched coarse (cells of 4 voxels) then fine, within max_shift_m along each axis. The shift is taken when it
// overlaps at least min_gain more voxels than no shift does; otherwise none (poses that agree keep theirs).
#pragma once

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

struct GridShift {
  Eigen::Vector3i voxels = Eigen::Vector3i::Zero();  // to add to the current grid's voxel indices
  long long overlap = 0;                             // occupied current voxels on occupied prior ones, after the shift
  long long overlap_unshifted = 0;                   // ... without it
  bool applied = false;                              // the shift beats no shift by min_gain
  // The shift that overlaps the most, taken or not, and its overlap. Where it is not zero and overlaps more than
  // no shift, but by less than min_gain, the alignment is undecided (Undecided).
  Eigen::Vector3i best = Eigen::Vector3i::Zero();
  long long best_overlap = 0;
  bool Undecided() const { return !applied && best != Eigen::Vector3i::Zero() && best_overlap > overlap_unshifted; }
};

class EvidenceGrid;

// The search against one prior grid, whose occupied voxels (fine and in coarse cells) are gathered once: the
// onboard checks search again as the current grid grows.
class ShiftSearch {
 public:
  ShiftSearch(const EvidenceGridData& prior, const GridAlignmentOptions& options);
  // The shift of `current` onto the prior (none when their voxel sizes differ).
  GridShift Find(const EvidenceGridData& current) const;
  GridShift Find(const EvidenceGrid& current) const;  // a grid still being built, read in place

 private:
  GridShift Find(const std::vector<Eigen::Vector3i>& current_occupied) const;

  double voxel_size_;
  GridAlignmentOptions options_;
  std::unordered_set<std::uint64_t> fine_, coarse_;  // the prior's occupied voxel keys; empty: no search
};

// The shift of `current` onto `prior` (both must have the same voxel size; none otherwise).
GridShift FindGridShift(const EvidenceGridData& prior, const EvidenceGridData& current,
                        const GridAlignmentOptions& options);
// The same for a grid still being built, read in place (onboard, while flying).
GridShift FindGridShift(const EvidenceGridData& prior, const EvidenceGrid& current,
                        const GridAlignmentOptions& options);

// "moved by (x, y, z) m onto REFERENCE's surfaces: ... of its occupied voxels meet REFERENCE's, ... before".
std::string DescribeShift(const GridShift& shift, double voxel_size, const std::string& reference);

// `record` moved by `shift_voxels` whole voxels of its grid: grid, objects, views and route poses.
void ShiftRecord(const Eigen::Vector3i& shift_voxels, PatrolRecord* record);
// `record`'s objects, views and route poses moved by `shift_m` (its grid, if any, stays).
void MoveRecordPoses(const Eigen::Vector3d& shift_m, PatrolRecord* record);

}  // namespace patrolmap::change
