// Evidence grid of one patrol (paper 004) and the geometry change between two.
// Each depth ray adds a hit to the voxel it ends in and a pass to every voxel
// it crosses before; a voxel's occupancy is hits / (hits + passes). A voxel
// observed in both patrols whose occupancy differs by more than a threshold
// has changed; changed voxels join the region whose centroid lies within a
// distance (else start one), overlapping regions merge into the larger, and
// small regions are dropped. Unobserved space is never a change.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

class EvidenceGrid {
 public:
  explicit EvidenceGrid(const EvidenceGridOptions& options);

  // Traces the rays of one depth image (metres along the optical axis, 0 = no
  // return) seen from `pose`, one every RayStep() pixels from RayStep() / 2 in both directions. Depth whose
  // range error grows as sigma(r) = range_sigma_per_m2 * r^2 (stereo; 0 for exact depth) carves free space only
  // up to free_space_sigmas * sigma(r) before each return. `error_scale` (CV_32F, optional): at each traced pixel
  // the factor on sigma(r) of depth averaged over several frames (depth::DepthFusion); 0 or empty: 1.
  void Integrate(const cv::Mat& depth_m, const CameraIntrinsics& camera, const CameraPoseSample& pose,
                 double range_sigma_per_m2 = 0.0, const cv::Mat& error_scale = cv::Mat());
  // The pixel spacing of the rays traced in a depth image `cols` wide (options.rays_per_row a row).
  int RayStep(int cols) const;
  // Traces one ray from `origin` towards `end`; `hit` when it ends on a surface. The voxels of the last
  // `hold_back_m` before the end are neither free nor hit.
  void TraceRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& end, bool hit, double hold_back_m = 0.0);

  std::size_t voxel_count() const { return size_; }
  // The most voxels options.memory_mb holds: the table is a power of two of 16-byte slots, at most half of
  // them used, and growing or shedding voxels copies it once.
  static std::size_t MaxVoxels(const EvidenceGridOptions& options);
  // Voxels dropped when the grid was full: the least recently observed quarter each time, never one the
  // current depth image reached. Their evidence is lost; a later patrol compares nothing there.
  long long evicted_voxels() const { return evicted_; }
  // Updates lost because the current depth image alone filled the grid.
  long long dropped_updates() const { return dropped_; }
  double voxel_size() const { return options_.voxel_size_m; }
  // The voxel at `index`, when the grid holds it (into `voxel`).
  bool Lookup(const Eigen::Vector3i& index, VoxelEvidence* voxel) const;
  // The indices of its occupied voxels (IsOccupied), in no order.
  std::vector<Eigen::Vector3i> OccupiedVoxels() const;
  EvidenceGridData ToData() const;
  // ToData(), and the table's memory given back (the grid is as a new one afterwards, its eviction count
  // kept): the end of a patrol.
  EvidenceGridData TakeData();

 private:
  struct Slot {
    std::uint64_t key = 0;  // 0 = empty
    std::uint16_t hits = 0, passes = 0;
    std::uint32_t stamp = 0;  // the depth image that last reached it (Integrate calls)
  };
  static_assert(sizeof(Slot) == 16, "MaxVoxels counts 16-byte slots");
  Slot* Find(std::uint64_t key);
  const Slot* Probe(std::uint64_t key) const;  // the slot of `key`, or null; never inserts
  Slot* Insert(std::uint64_t key);
  void Grow();
  bool Evict();

  EvidenceGridOptions options_;
  std::size_t max_voxels_;
  std::vector<Slot> slots_;
  std::size_t size_ = 0;
  std::uint32_t stamp_ = 0;
  long long evicted_ = 0;
  long long dropped_ = 0;
};

// Voxel key helpers (index = round(coordinate / voxel_size)).
Eigen::Vector3i VoxelIndex(const Eigen::Vector3d& point, double voxel_size);
// A voxel index packed into one never-zero number (21 bits an axis, indices within +-2^20): the grid's hash key.
std::uint64_t VoxelKey(const Eigen::Vector3i& index);

// A voxel counts as occupied when most rays ended in it and at least two did (false for nullptr).
bool IsOccupied(const VoxelEvidence* voxel);

// The counts of voxel `index`, or nullptr (binary search in the sorted data).
const VoxelEvidence* FindVoxel(const EvidenceGridData& grid, const Eigen::Vector3i& index);

// Reads one patrol's evidence grid: true and the voxel at `index` when the grid holds it.
using VoxelLookup = std::function<bool(const Eigen::Vector3i& index, VoxelEvidence* voxel)>;
VoxelLookup LookupIn(const EvidenceGridData& grid);  // the grid must outlive the lookup
// A grid still being built (onboard), read in place; its voxel i answers for index i + shift (a patrol aligned
// onto the map's by whole voxels, change/grid_alignment.h).
VoxelLookup LookupIn(const EvidenceGrid& grid, const Eigen::Vector3i& shift = Eigen::Vector3i::Zero());

struct GeometryRegion {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();  // voxel-centre extent
  int voxels = 0;
  int appeared = 0;    // voxels that became occupied
  int vanished = 0;    // voxels that became free
  double score = 0.0;  // mean occupancy change
};

struct GeometryChange {
  double voxel_size = 0.0;
  long long compared_voxels = 0;   // observed enough in both patrols
  long long surface_voxels = 0;    // ... and occupied in at least one of them
  long long differing_voxels = 0;  // ... of those, changed beyond the surface tolerance (before the region tests)
  bool poses_disagree = false;     // differing / surface voxels above max_differing_share: no region reported
  double DifferingShare() const {
    return surface_voxels > 0 ? static_cast<double>(differing_voxels) / static_cast<double>(surface_voxels) : 0.0;
  }
  // Voxels each patrol's grid dropped at its memory budget (change.grid.memory_mb): nothing is compared there.
  long long evicted_prior = 0, evicted_current = 0;
  std::string depth_prior, depth_current;       // where each grid's depth came from (PatrolRecord::depth_source)
  std::vector<Eigen::Vector3i> changed_voxels;  // of the reported regions, sorted
  std::vector<float> changed_deltas;            // ... and each one's occupancy now minus before (> 0: appeared)
  std::vector<GeometryRegion> regions;          // largest first
  // Where the grids were compared: the cells of kComparedCellM a side (world index floor(x / kComparedCellM)) holding
  // a compared voxel, sorted. A change another channel found outside them was not compared in 3D: no depth of one
  // patrol or the other reached it (a rig's or the flight's range), so "no geometry change" says nothing there.
  static constexpr double kComparedCellM = 1.0;
  std::vector<Eigen::Vector3i> compared_cells;
  // Whether a compared cell lies at `point` or beside it (its 26 neighbours).
  bool ComparedNear(const Eigen::Vector3d& point) const;
};

// Whether two patrols whose camera poses came from `prior_source` and `current_source` (PatrolRecord::pose_source)
// share a frame with z up: one came from GPS (east, north, up), whose alignment leaves sheets of ground. Other
// sources may not have z up (a KITTI pose file has y down).
bool PosesHaveZUp(const std::string& prior_source, const std::string& current_source);
// Whether z points up in the frame of such patrols: every pose source but a --poses file (a KITTI one has y down)
// gives a frame with gravity along -z.
bool ZPointsUp(const std::string& prior_source, const std::string& current_source);
// `options` for two such patrols: sheets of ground are dropped (drop_ground_sheets) only where PosesHaveZUp, and
// regions under a cap (min_capped_columns) only where ZPointsUp.
GeometryDiffOptions ForPoseSources(GeometryDiffOptions options, const std::string& prior_source,
                                   const std::string& current_source);
// The same for the class-agnostic objects (GeometryObjectOptions::drop_ground_sheets).
GeometryObjectOptions ForPoseSources(GeometryObjectOptions options, const std::string& prior_source,
                                     const std::string& current_source);

// The ground's voxel level around a box of voxels `low`-`high` (indices, z up): the median, over the columns of a
// ring `ring_m` wide around the box, of each column's lowest voxel that holds a return in `grid`, searched from 3 m
// below the box's foot up to `above` voxels above it. None when no column holds one. Sheets of ground (DiffGrids)
// and the class-agnostic objects (GeometryObjects) both stand on it.
std::optional<int> GroundAround(const Eigen::Vector3i& low, const Eigen::Vector3i& high, double voxel, double ring_m,
                                int above, const VoxelLookup& grid);

// Fails (returns false) when the grids have different voxel sizes or none.
bool DiffGrids(const EvidenceGridData& before, const EvidenceGridData& after, const GeometryDiffOptions& options,
               GeometryChange* change);
// The same against a grid still being built, read in place (no copy of its voxels): the onboard checks while
// flying. Its voxel i is compared at index i + after_shift (LookupIn). Equal to DiffGrids(before, after.ToData()
// shifted, ...).
bool DiffGrids(const EvidenceGridData& before, const EvidenceGrid& after, const GeometryDiffOptions& options,
               GeometryChange* change, const Eigen::Vector3i& after_shift = Eigen::Vector3i::Zero());

}  // namespace patrolmap::change
