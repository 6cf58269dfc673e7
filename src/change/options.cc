#include "patrolmap/change/options.h"

namespace patrolmap::change {
namespace {

bool Check(bool ok, const char* message, std::string* error) {
  if (!ok && error != nullptr) *error = message;
  return ok;
}

}  // namespace

bool ChangeOptions::IsValid(std::string* error) const {
  return Check(appearance.ratio > 0 && appearance.ratio <= 1, "change.appearance.ratio must lie in (0, 1]", error) &&
         Check(appearance.min_inliers >= 4, "change.appearance.min_inliers must be at least 4", error) &&
         Check(appearance.search_radius_px >= 0, "change.appearance.search_radius_px must not be negative", error) &&
         Check(appearance.structure_sigma_px > 0, "change.appearance.structure_sigma_px must be positive", error) &&
         Check(object_map.centroid_gate_m > 0, "change.object_map.centroid_gate_m must be positive", error) &&
         Check(object_map.point_voxel_m > 0, "change.object_map.point_voxel_m must be positive", error) &&
         Check(object_map.min_pair_fraction >= 0 && object_map.min_pair_fraction <= 1,
               "change.object_map.min_pair_fraction must lie in [0, 1]", error) &&
         Check(object_map.min_detections >= 1, "change.object_map.min_detections must be at least 1", error) &&
         Check(objects.match_distance_m > 0, "change.objects.match_distance_m must be positive", error) &&
         Check(objects.min_visible_fraction >= 0 && objects.min_visible_fraction <= 1,
               "change.objects.min_visible_fraction must lie in [0, 1]", error) &&
         Check(objects.min_expected_detections > 0, "change.objects.min_expected_detections must be positive", error) &&
         Check(objects.physical_weight >= 0 && objects.appearance_weight >= 0,
               "change.objects weights must not be negative", error) &&
         Check(grid.voxel_size_m >= 0.02, "change.grid.voxel_size_m must be at least 0.02", error) &&
         Check(grid.max_range_m > 0 && grid.max_range_m / grid.voxel_size_m < 1e5,
               "change.grid.max_range_m must be positive and under 100000 voxels", error) &&
         Check(grid.rays_per_row >= 1, "change.grid.rays_per_row must be at least 1", error) &&
         Check(grid.rate_hz > 0, "change.grid.rate_hz must be positive", error) &&
         Check(grid.max_voxels > 0, "change.grid.max_voxels must be positive", error) &&
         Check(geometry.min_occupancy_change > 0 && geometry.min_occupancy_change < 1,
               "change.geometry.min_occupancy_change must lie in (0, 1)", error) &&
         Check(geometry.min_observations >= 1, "change.geometry.min_observations must be at least 1", error);
}

}  // namespace patrolmap::change
