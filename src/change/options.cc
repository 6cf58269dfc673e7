#include "patrolmap/change/options.h"

#include "patrolmap/core/option_check.h"

namespace patrolmap::change {
namespace {

void CheckAppearance(const AppearanceOptions& a, OptionCheck* check) {
  check->AboveAtMost("change.appearance.ratio", a.ratio, 0.0, 1.0)
      .AboveAtMost("change.appearance.inlier_threshold_px", a.inlier_threshold_px, 0.0, 100.0)
      .InRange("change.appearance.min_inliers", a.min_inliers, 4, 100000)
      .InRange("change.appearance.blur_sigma_px", a.blur_sigma_px, 0.0, 50.0)
      .InRange("change.appearance.search_radius_px", a.search_radius_px, 0, 50)
      .InRange("change.appearance.min_difference", a.min_difference, 0.0, 255.0)
      .InRange("change.appearance.min_structure_change", a.min_structure_change, 0.0, 2.0)
      .AboveAtMost("change.appearance.structure_sigma_px", a.structure_sigma_px, 0.0, 50.0)
      .InRange("change.appearance.closing_px", a.closing_px, 0, 50)
      .InRange("change.appearance.min_area_fraction", a.min_area_fraction, 0.0, 1.0)
      .InRange("change.appearance.min_side_fraction", a.min_side_fraction, 0.0, 1.0)
      .InRange("change.appearance.min_unmatched_share", a.min_unmatched_share, 0.0, 1.0)
      .InRange("change.appearance.parallax_search_px", a.parallax_search_px, 0, 100)
      .InRange("change.appearance.horizontal_parallax_search_px", a.horizontal_parallax_search_px, 0, 200)
      .InRange("change.appearance.max_shifted_similarity", a.max_shifted_similarity, -1.0, 1.0)
      .InRange("change.appearance.edge_margin_px", a.edge_margin_px, 0, 1000)
      .InRange("change.appearance.max_planes", a.max_planes, 1, 8);
}

void CheckObjectMap(const ObjectMapOptions& m, OptionCheck* check) {
  check->AboveAtMost("change.object_map.centroid_gate_m", m.centroid_gate_m, 0.0, 1000.0)
      .AboveAtMost("change.object_map.pair_distance_m", m.pair_distance_m, 0.0, 100.0)
      .InRange("change.object_map.min_pair_fraction", m.min_pair_fraction, 0.0, 1.0)
      .InRange("change.object_map.point_voxel_m", m.point_voxel_m, 0.005, 10.0)
      .AboveAtMost("change.object_map.segment_depth_m", m.segment_depth_m, 0.0, 100.0)
      .InRange("change.object_map.max_segment_samples", m.max_segment_samples, 1, 1000000)
      .InRange("change.object_map.min_box_iou", m.min_box_iou, 0.0, 1.0)
      .AboveAtMost("change.object_map.category_sigma_m", m.category_sigma_m, 0.0, 1000.0)
      .AboveAtMost("change.object_map.vehicle_sigma_m", m.vehicle_sigma_m, 0.0, 1000.0)
      .InRange("change.object_map.min_category_prior", m.min_category_prior, 0.0, 1.0)
      .InRange("change.object_map.merge_distance_m", m.merge_distance_m, 0.0, 1000.0)
      .InRange("change.object_map.min_detections", m.min_detections, 1, 1000000)
      .InRange("change.object_map.max_objects", m.max_objects, 1, 10000000)
      .AboveAtMost("change.object_map.max_range_m", m.max_range_m, 0.0, 10000.0);
}

void CheckObjects(const ObjectDiffOptions& o, OptionCheck* check) {
  check->AboveAtMost("change.objects.match_distance_m", o.match_distance_m, 0.0, 1000.0)
      .InRange("change.objects.max_move_m", o.max_move_m, 0.0, 10000.0)
      .InRange("change.objects.physical_weight", o.physical_weight, 0.0, 1.0)
      .AboveAtMost("change.objects.max_visible_range_m", o.max_visible_range_m, 0.0, 10000.0)
      .InRange("change.objects.min_visible_fraction", o.min_visible_fraction, 0.0, 1.0)
      .AboveAtMost("change.objects.min_expected_detections", o.min_expected_detections, 0.0, 1e6)
      .InRange("change.objects.max_top_difference_m", o.max_top_difference_m, 0.0, 1000.0);
}

void CheckGrid(const EvidenceGridOptions& g, OptionCheck* check) {
  check->InRange("change.grid.voxel_size_m", g.voxel_size_m, 0.02, 100.0)
      .AboveAtMost("change.grid.max_range_m", g.max_range_m, 0.0, 1000.0)
      .Holds("change.grid.max_range_m", g.max_range_m, g.max_range_m / g.voxel_size_m < 1e4,
             "must be under 10000 voxels (change.grid.voxel_size_m)")
      .InRange("change.grid.rays_per_row", g.rays_per_row, 1, 10000)
      .AboveAtMost("change.grid.rate_hz", g.rate_hz, 0.0, 1000.0)
      .InRange("change.grid.free_space_sigmas", g.free_space_sigmas, 0.0, 10.0)
      .AboveAtMost("change.grid.max_hit_sigma_m", g.max_hit_sigma_m, 0.0, 1000.0)
      .InRange("change.grid.memory_mb", g.memory_mb, 1.0, 65536.0);
}

void CheckGeometry(const GeometryDiffOptions& g, OptionCheck* check) {
  check
      ->Holds("change.geometry.min_occupancy_change", g.min_occupancy_change,
              g.min_occupancy_change > 0.0 && g.min_occupancy_change < 1.0, "must be a number in (0, 1)")
      .InRange("change.geometry.max_free_occupancy", g.max_free_occupancy, 0.0, 1.0)
      .InRange("change.geometry.min_observations", g.min_observations, 1, 1000000)
      .InRange("change.geometry.min_free_ratio", g.min_free_ratio, 0.0, 1000.0)
      .InRange("change.geometry.surface_tolerance_voxels", g.surface_tolerance_voxels, 0, 10)
      .InRange("change.geometry.join_distance_m", g.join_distance_m, 0.0, 1000.0)
      .InRange("change.geometry.min_region_voxels", g.min_region_voxels, 1, 100000000)
      .InRange("change.geometry.min_region_width_m", g.min_region_width_m, 0.0, 1000.0)
      .InRange("change.geometry.min_shift_thickness_voxels", g.min_shift_thickness_voxels, 0.0, 100.0)
      .InRange("change.geometry.min_capped_columns", g.min_capped_columns, 0, 100000)
      .InRange("change.geometry.cap_search_voxels", g.cap_search_voxels, 1, 100)
      .InRange("change.geometry.max_differing_share", g.max_differing_share, 0.0, 1.0);
}

void CheckGeometryObjects(const GeometryObjectOptions& g, OptionCheck* check) {
  check->InRange("change.geometry_objects.cluster_gap_voxels", g.cluster_gap_voxels, 1, 10)
      .InRange("change.geometry_objects.min_voxels", g.min_voxels, 1, 100000000)
      .InRange("change.geometry_objects.ground_search_m", g.ground_search_m, 0.0, 5.0)
      .InRange("change.geometry_objects.footprint_gap_m", g.footprint_gap_m, 0.0, 100.0)
      .InRange("change.geometry_objects.min_surface_occupancy", g.min_surface_occupancy, 0.0, 1.0)
      .InRange("change.geometry_objects.ground_clearance_voxels", g.ground_clearance_voxels, 0, 100)
      .AboveAtMost("change.geometry_objects.max_size_m", g.max_size_m, 0.0, 10000.0)
      .InRange("change.geometry_objects.max_move_m", g.max_move_m, 0.0, 10000.0)
      .InRange("change.geometry_objects.max_top_difference_m", g.max_top_difference_m, 0.0, 1000.0)
      .InRange("change.geometry_objects.min_shape_overlap", g.min_shape_overlap, 0.0, 1.0)
      .AboveAtMost("change.geometry_objects.shape_tolerance_m", g.shape_tolerance_m, 0.0, 100.0)
      .InRange("change.geometry_objects.shape_search_m", g.shape_search_m, 0.0, 10.0)
      .Holds("change.geometry_objects.shape_search_m", g.shape_search_m, g.shape_search_m <= 10.0 * g.shape_tolerance_m,
             "must be at most 10 times change.geometry_objects.shape_tolerance_m (the search's steps are at least "
             "half of it)")
      .InRange("change.geometry_objects.physical_weight", g.physical_weight, 0.0, 1.0)
      .InRange("change.geometry_objects.detection_margin_m", g.detection_margin_m, 0.0, 100.0);
}

void CheckRouteFrames(const RouteFrameOptions& r, OptionCheck* check) {
  check->InRange("change.route_frames.interval_s", r.interval_s, 0.0, 3600.0)
      .InRange("change.route_frames.max_width", r.max_width, 16, 2048)
      .InRange("change.route_frames.jpeg_quality", r.jpeg_quality, 1, 100)
      .InRange("change.route_frames.memory_mb", r.memory_mb, 0.1, 65536.0);
}

void CheckRoute(const RouteCompareOptions& r, OptionCheck* check) {
  check->InRange("change.route.search_window_s", r.search_window_s, 0.0, 3600.0)
      .InRange("change.route.max_features", r.max_features, 16, 100000)
      .InRange("change.route.max_candidates", r.max_candidates, 1, 1000)
      .InRange("change.route.min_votes", r.min_votes, 1, 1000)
      .InRange("change.route.min_overlap", r.min_overlap, 0.0, 1.0)
      .InRange("change.route.depth.num_disparities", r.depth.num_disparities, 16, 1024)
      .Holds("change.route.depth.num_disparities", r.depth.num_disparities, r.depth.num_disparities % 16 == 0,
             "must be a multiple of 16")
      .AboveAtMost("change.route.depth.min_change_m", r.depth.min_change_m, 0.0, 1000.0)
      .InRange("change.route.depth.sigmas", r.depth.sigmas, 0.0, 100.0)
      .InRange("change.route.depth.parallax_min_marked_share", r.depth.parallax_min_marked_share, 0.0, 1.0)
      .InRange("change.route.depth.parallax_known_share", r.depth.parallax_known_share, 0.0, 1.0)
      .InRange("change.route.depth.parallax_slack_px", r.depth.parallax_slack_px, 0, 100);
}

}  // namespace

bool ChangeOptions::IsValid(std::string* error) const {
  OptionCheck check(error);
  CheckAppearance(appearance, &check);
  CheckObjectMap(object_map, &check);
  CheckObjects(objects, &check);
  CheckGrid(grid, &check);
  CheckGeometry(geometry, &check);
  check.InRange("change.alignment.max_shift_m", alignment.max_shift_m, 0.0, 100.0)
      .InRange("change.alignment.min_gain", alignment.min_gain, 0.0, 10.0)
      .InRange("change.alignment.min_differing_share", alignment.min_differing_share, 0.0, 1.0);
  CheckGeometryObjects(geometry_objects, &check);
  CheckRouteFrames(route_frames, &check);
  CheckRoute(route, &check);
  check.InRange("change.location.min_depth_share", location.min_depth_share, 0.0, 1.0)
      .InRange("change.location.min_ray_angle_deg", location.min_ray_angle_deg, 0.0, 90.0)
      .AboveAtMost("change.location.max_range_m", location.max_range_m, 0.0, 10000.0);
  return check.ok();
}

}  // namespace patrolmap::change
