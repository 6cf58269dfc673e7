// Class-agnostic objects from changed geometry, for logs without an object detector (paper 003's clustering of
// changed space). The changed voxels of a GeometryChange that became occupied (appeared) and those that became
// free (vanished) are grouped apart into clusters of voxels at most cluster_gap_voxels apart. With complete_objects
// each cluster then grows in its patrol's grid into the object it belongs to (the occupied voxels above the ground
// connected to it; paper 003 segments the changed space in the mission's map), and clusters that grew into one
// object merge, and so do clusters whose footprints meet (a side and a top the grid does not connect). A cluster of at
// least min_voxels and at most max_size_m across is an object: appeared, it is new; vanished, it was removed. A
// vanished and an appeared cluster are one object moved when they lie within max_move_m, their tops differ by at most
// max_top_difference_m and each, registered onto the other (centroids aligned, then the best horizontal shift of up to
// shape_search_m each way in steps of a voxel or half shape_tolerance_m, since a partial view pulls a centroid off the
// object's centre; rotation by RegisterRotation), has at least min_shape_overlap of its voxels within shape_tolerance_m
// of the other's; pairs are taken greedily by paper 003's weighted distance (physical_weight x distance / max_move_m +
// (1 - physical_weight) x (1 - overlap)). Unchanged space never makes an object, so these objects are never persistent
// or unobserved. Detections (objects0/) take precedence: a cluster whose box, grown by detection_margin_m, holds the
// centroid of an object its patrol's detector mapped, or at least half of whose voxels lie in that object's box grown
// by detection_margin_m, is left to the detected objects' states.
#pragma once

#include <vector>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

// The label of a class-agnostic object.
constexpr char kClassAgnosticLabel[] = "object";

// A cluster of changed voxels of one sign: voxel centres [m, world frame], their extent (voxel centres) and
// their mean occupancy change (absolute).
struct VoxelCluster {
  std::vector<Eigen::Vector3i> voxels;
  std::vector<Eigen::Vector3f> points;  // their centres
  Eigen::AlignedBox3d box;
  double mean_change = 0.0;
  void Add(const Eigen::Vector3i& index, double voxel_size);
  Eigen::Vector3d Centroid() const;
  // Where the object stands: the centre of the extent. A camera sees an object's near faces and top, so the
  // extent (the top spans the footprint) centres it better than the centroid, which leans to the near side.
  Eigen::Vector3d Position() const;
};

// The clusters of the changed voxels that appeared (`appeared` true) or vanished, in the order of their first
// voxel in change.changed_voxels.
std::vector<VoxelCluster> ClusterChangedVoxels(const GeometryChange& change, bool appeared, int gap_voxels);

// The objects that appeared, vanished or moved between the two patrols' grids (see above). With a patrol's grid
// (`prior_grid`, `current_grid`; may be empty), each cluster is completed there into the whole object it belongs to.
// `prior_detected` and `current_detected` are the detected objects of each patrol (may be empty).
std::vector<ObjectChange> GeometryObjects(const GeometryChange& change, const VoxelLookup& prior_grid,
                                          const VoxelLookup& current_grid, const std::vector<MapObject>& prior_detected,
                                          const std::vector<MapObject>& current_detected,
                                          const GeometryObjectOptions& options);

}  // namespace patrolmap::change
