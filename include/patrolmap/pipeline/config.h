// The run configuration: every stage's options struct, loaded from YAML.
// config/default.yaml mirrors these structs one to one; keys are the dotted
// paths listed by VisitConfig (e.g. flow.voting.accept).
#pragma once

#include <string>

#include "patrolmap/change/options.h"
#include "patrolmap/core/status.h"
#include "patrolmap/depth/options.h"
#include "patrolmap/flow/options.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/place/place_recognizer.h"

namespace patrolmap::pipeline {

struct Config {
  io::ImageFolderOptions input;
  flow::KeyLocationOptions flow;
  place::PlaceOptions place;
  ::patrolmap::change::ChangeOptions change;
  depth::DepthOptions depth;
  graph::MapRetention map;

  bool IsValid(std::string* error) const;
};

// Calls visitor.Field(path, &field) for every configurable field, in file order.
template <typename Visitor>
void VisitConfig(Config* config, Visitor* visitor) {
  visitor->Field("input.frame_rate_hz", &config->input.frame_rate_hz);
  flow::KeyLocationOptions& flow = config->flow;
  visitor->Field("flow.frames.rate_hz", &flow.frames.rate_hz);
  visitor->Field("flow.frames.scale", &flow.frames.scale);
  visitor->Field("flow.edges.canny_low", &flow.edges.canny_low);
  visitor->Field("flow.edges.canny_high", &flow.edges.canny_high);
  visitor->Field("flow.edges.max_points", &flow.edges.max_points);
  visitor->Field("flow.edges.grid_columns", &flow.edges.grid_columns);
  visitor->Field("flow.edges.grid_rows", &flow.edges.grid_rows);
  visitor->Field("flow.edges.border", &flow.edges.border);
  visitor->Field("flow.tracker.window_size", &flow.tracker.window_size);
  visitor->Field("flow.tracker.pyramid_levels", &flow.tracker.pyramid_levels);
  visitor->Field("flow.tracker.max_iterations", &flow.tracker.max_iterations);
  visitor->Field("flow.tracker.epsilon", &flow.tracker.epsilon);
  visitor->Field("flow.tracker.min_eigen_threshold", &flow.tracker.min_eigen_threshold);
  visitor->Field("flow.tracker.predict_from_previous", &flow.tracker.predict_from_previous);
  visitor->Field("flow.tracker.max_forward_backward_px", &flow.tracker.max_forward_backward_px);
  visitor->Field("flow.voting.theta_bins", &flow.voting.theta_bins);
  visitor->Field("flow.voting.r_bin_fraction", &flow.voting.r_bin_fraction);
  visitor->Field("flow.voting.accept", &flow.voting.accept);
  visitor->Field("flow.voting.reject", &flow.voting.reject);
  visitor->Field("flow.voting.max_votes", &flow.voting.max_votes);
  visitor->Field("flow.response.quantity", &flow.response.quantity);
  visitor->Field("flow.response.derotate_with_imu", &flow.response.derotate_with_imu);
  visitor->Field("flow.response.normalise_by_speed", &flow.response.normalise_by_speed);
  visitor->Field("flow.response.reference_speed_mps", &flow.response.reference_speed_mps);
  visitor->Field("flow.response.min_speed_mps", &flow.response.min_speed_mps);
  visitor->Field("flow.smoothing.window_s", &flow.smoothing.window_s);
  visitor->Field("flow.smoothing.mode", &flow.smoothing.mode);
  visitor->Field("flow.extrema.min_change", &flow.extrema.min_change);
  visitor->Field("flow.extrema.min_time_s", &flow.extrema.min_time_s);
  place::PlaceOptions& place = config->place;
  visitor->Field("place.max_features", &place.max_features);
  visitor->Field("place.root_sift", &place.root_sift);
  visitor->Field("place.candidates", &place.candidates);
  visitor->Field("place.exclude_recent_s", &place.exclude_recent_s);
  visitor->Field("place.exclude_recent_images", &place.exclude_recent_images);
  visitor->Field("place.ratio", &place.ratio);
  visitor->Field("place.min_matched_fraction", &place.min_matched_fraction);
  visitor->Field("place.method", &place.method);
  visitor->Field("place.inlier_threshold_px", &place.inlier_threshold_px);
  visitor->Field("place.min_inliers", &place.min_inliers);
  visitor->Field("place.max_log_nfa", &place.max_log_nfa);
  visitor->Field("place.accept_best", &place.accept_best);
  visitor->Field("place.one_to_one", &place.one_to_one);
  visitor->Field("place.descriptor_bits", &place.descriptor_bits);
  visitor->Field("place.query_words", &place.query.max_words);
  visitor->Field("place.rescored_entries", &place.query.rescored);
  visitor->Field("place.query_min_skipped_postings", &place.query.min_skipped_postings);
  auto& change = config->change;
  visitor->Field("change.appearance.ratio", &change.appearance.ratio);
  visitor->Field("change.appearance.inlier_threshold_px", &change.appearance.inlier_threshold_px);
  visitor->Field("change.appearance.min_inliers", &change.appearance.min_inliers);
  visitor->Field("change.appearance.blur_sigma_px", &change.appearance.blur_sigma_px);
  visitor->Field("change.appearance.search_radius_px", &change.appearance.search_radius_px);
  visitor->Field("change.appearance.min_difference", &change.appearance.min_difference);
  visitor->Field("change.appearance.min_structure_change", &change.appearance.min_structure_change);
  visitor->Field("change.appearance.structure_sigma_px", &change.appearance.structure_sigma_px);
  visitor->Field("change.appearance.closing_px", &change.appearance.closing_px);
  visitor->Field("change.appearance.min_area_fraction", &change.appearance.min_area_fraction);
  visitor->Field("change.appearance.min_side_fraction", &change.appearance.min_side_fraction);
  visitor->Field("change.appearance.min_unmatched_share", &change.appearance.min_unmatched_share);
  visitor->Field("change.appearance.parallax_search_px", &change.appearance.parallax_search_px);
  visitor->Field("change.appearance.horizontal_parallax_search_px", &change.appearance.horizontal_parallax_search_px);
  visitor->Field("change.appearance.max_shifted_similarity", &change.appearance.max_shifted_similarity);
  visitor->Field("change.appearance.edge_margin_px", &change.appearance.edge_margin_px);
  visitor->Field("change.appearance.both_ways", &change.appearance.both_ways);
  visitor->Field("change.appearance.max_planes", &change.appearance.max_planes);
  visitor->Field("change.object_map.centroid_gate_m", &change.object_map.centroid_gate_m);
  visitor->Field("change.object_map.pair_distance_m", &change.object_map.pair_distance_m);
  visitor->Field("change.object_map.min_pair_fraction", &change.object_map.min_pair_fraction);
  visitor->Field("change.object_map.point_voxel_m", &change.object_map.point_voxel_m);
  visitor->Field("change.object_map.segment_depth_m", &change.object_map.segment_depth_m);
  visitor->Field("change.object_map.max_segment_samples", &change.object_map.max_segment_samples);
  visitor->Field("change.object_map.min_box_iou", &change.object_map.min_box_iou);
  visitor->Field("change.object_map.category_sigma_m", &change.object_map.category_sigma_m);
  visitor->Field("change.object_map.vehicle_sigma_m", &change.object_map.vehicle_sigma_m);
  visitor->Field("change.object_map.min_category_prior", &change.object_map.min_category_prior);
  visitor->Field("change.object_map.merge_distance_m", &change.object_map.merge_distance_m);
  visitor->Field("change.object_map.min_detections", &change.object_map.min_detections);
  visitor->Field("change.object_map.max_range_m", &change.object_map.max_range_m);
  visitor->Field("change.object_map.max_objects", &change.object_map.max_objects);
  visitor->Field("change.objects.match_distance_m", &change.objects.match_distance_m);
  visitor->Field("change.objects.max_move_m", &change.objects.max_move_m);
  visitor->Field("change.objects.physical_weight", &change.objects.physical_weight);
  visitor->Field("change.objects.max_visible_range_m", &change.objects.max_visible_range_m);
  visitor->Field("change.objects.min_visible_fraction", &change.objects.min_visible_fraction);
  visitor->Field("change.objects.min_expected_detections", &change.objects.min_expected_detections);
  visitor->Field("change.objects.max_top_difference_m", &change.objects.max_top_difference_m);
  visitor->Field("change.grid.voxel_size_m", &change.grid.voxel_size_m);
  visitor->Field("change.grid.max_range_m", &change.grid.max_range_m);
  visitor->Field("change.grid.rays_per_row", &change.grid.rays_per_row);
  visitor->Field("change.grid.rate_hz", &change.grid.rate_hz);
  visitor->Field("change.grid.free_space_sigmas", &change.grid.free_space_sigmas);
  visitor->Field("change.grid.max_hit_sigma_m", &change.grid.max_hit_sigma_m);
  visitor->Field("change.grid.memory_mb", &change.grid.memory_mb);
  visitor->Field("change.geometry.min_occupancy_change", &change.geometry.min_occupancy_change);
  visitor->Field("change.geometry.max_free_occupancy", &change.geometry.max_free_occupancy);
  visitor->Field("change.geometry.min_observations", &change.geometry.min_observations);
  visitor->Field("change.geometry.min_free_ratio", &change.geometry.min_free_ratio);
  visitor->Field("change.geometry.surface_tolerance_voxels", &change.geometry.surface_tolerance_voxels);
  visitor->Field("change.geometry.vertical_tolerance", &change.geometry.vertical_tolerance);
  visitor->Field("change.geometry.join_distance_m", &change.geometry.join_distance_m);
  visitor->Field("change.geometry.min_region_voxels", &change.geometry.min_region_voxels);
  visitor->Field("change.geometry.min_region_width_m", &change.geometry.min_region_width_m);
  visitor->Field("change.geometry.drop_ground_sheets", &change.geometry.drop_ground_sheets);
  visitor->Field("change.geometry.min_shift_thickness_voxels", &change.geometry.min_shift_thickness_voxels);
  visitor->Field("change.geometry.min_capped_columns", &change.geometry.min_capped_columns);
  visitor->Field("change.geometry.cap_search_voxels", &change.geometry.cap_search_voxels);
  visitor->Field("change.geometry.max_differing_share", &change.geometry.max_differing_share);
  visitor->Field("change.alignment.max_shift_m", &change.alignment.max_shift_m);
  visitor->Field("change.alignment.min_gain", &change.alignment.min_gain);
  visitor->Field("change.alignment.min_differing_share", &change.alignment.min_differing_share);
  visitor->Field("change.geometry_objects.enabled", &change.geometry_objects.enabled);
  visitor->Field("change.geometry_objects.cluster_gap_voxels", &change.geometry_objects.cluster_gap_voxels);
  visitor->Field("change.geometry_objects.min_voxels", &change.geometry_objects.min_voxels);
  visitor->Field("change.geometry_objects.complete_objects", &change.geometry_objects.complete_objects);
  visitor->Field("change.geometry_objects.drop_ground_sheets", &change.geometry_objects.drop_ground_sheets);
  visitor->Field("change.geometry_objects.ground_search_m", &change.geometry_objects.ground_search_m);
  visitor->Field("change.geometry_objects.min_surface_occupancy", &change.geometry_objects.min_surface_occupancy);
  visitor->Field("change.geometry_objects.ground_clearance_voxels", &change.geometry_objects.ground_clearance_voxels);
  visitor->Field("change.geometry_objects.footprint_gap_m", &change.geometry_objects.footprint_gap_m);
  visitor->Field("change.geometry_objects.max_size_m", &change.geometry_objects.max_size_m);
  visitor->Field("change.geometry_objects.max_move_m", &change.geometry_objects.max_move_m);
  visitor->Field("change.geometry_objects.max_top_difference_m", &change.geometry_objects.max_top_difference_m);
  visitor->Field("change.geometry_objects.min_shape_overlap", &change.geometry_objects.min_shape_overlap);
  visitor->Field("change.geometry_objects.shape_tolerance_m", &change.geometry_objects.shape_tolerance_m);
  visitor->Field("change.geometry_objects.shape_search_m", &change.geometry_objects.shape_search_m);
  visitor->Field("change.geometry_objects.physical_weight", &change.geometry_objects.physical_weight);
  visitor->Field("change.geometry_objects.detection_margin_m", &change.geometry_objects.detection_margin_m);
  visitor->Field("change.route_frames.interval_s", &change.route_frames.interval_s);
  visitor->Field("change.route_frames.max_width", &change.route_frames.max_width);
  visitor->Field("change.route_frames.jpeg_quality", &change.route_frames.jpeg_quality);
  visitor->Field("change.route_frames.memory_mb", &change.route_frames.memory_mb);
  visitor->Field("change.route.enabled", &change.route.enabled);
  visitor->Field("change.route.search_window_s", &change.route.search_window_s);
  visitor->Field("change.route.max_features", &change.route.max_features);
  visitor->Field("change.route.max_candidates", &change.route.max_candidates);
  visitor->Field("change.route.min_votes", &change.route.min_votes);
  visitor->Field("change.route.min_overlap", &change.route.min_overlap);
  visitor->Field("change.route.depth.enabled", &change.route.depth.enabled);
  visitor->Field("change.route.depth.num_disparities", &change.route.depth.num_disparities);
  visitor->Field("change.route.depth.min_change_m", &change.route.depth.min_change_m);
  visitor->Field("change.route.depth.sigmas", &change.route.depth.sigmas);
  visitor->Field("change.route.depth.parallax_min_marked_share", &change.route.depth.parallax_min_marked_share);
  visitor->Field("change.route.depth.parallax_known_share", &change.route.depth.parallax_known_share);
  visitor->Field("change.route.depth.parallax_slack_px", &change.route.depth.parallax_slack_px);
  visitor->Field("change.location.min_depth_share", &change.location.min_depth_share);
  visitor->Field("change.location.min_ray_angle_deg", &change.location.min_ray_angle_deg);
  visitor->Field("change.location.max_range_m", &change.location.max_range_m);
  depth::DepthOptions& depth = config->depth;
  visitor->Field("depth.source", &depth.source);
  visitor->Field("depth.stereo.num_disparities", &depth.stereo.num_disparities);
  visitor->Field("depth.stereo.block_size", &depth.stereo.block_size);
  visitor->Field("depth.stereo.uniqueness_ratio", &depth.stereo.uniqueness_ratio);
  visitor->Field("depth.stereo.lr_check", &depth.stereo.lr_check);
  visitor->Field("depth.stereo.max_lr_difference", &depth.stereo.max_lr_difference);
  visitor->Field("depth.stereo.speckle_window", &depth.stereo.speckle_window);
  visitor->Field("depth.stereo.speckle_range", &depth.stereo.speckle_range);
  visitor->Field("depth.stereo.edge_radius_px", &depth.stereo.edge_radius_px);
  visitor->Field("depth.stereo.edge_jump_px", &depth.stereo.edge_jump_px);
  visitor->Field("depth.stereo.full_paths", &depth.stereo.full_paths);
  visitor->Field("depth.stereo.cancel_pixel_locking", &depth.stereo.cancel_pixel_locking);
  visitor->Field("depth.stereo.near_pass", &depth.stereo.near_pass);
  visitor->Field("depth.stereo.rate_hz", &depth.stereo.rate_hz);
  visitor->Field("depth.stereo.min_range_m", &depth.stereo.min_range_m);
  visitor->Field("depth.stereo.max_range_m", &depth.stereo.max_range_m);
  visitor->Field("depth.stereo.disparity_sigma_px", &depth.stereo.disparity_sigma_px);
  visitor->Field("depth.stereo.fuse_frames", &depth.stereo.fuse_frames);
  visitor->Field("depth.stereo.fuse_gate_sigmas", &depth.stereo.fuse_gate_sigmas);
  visitor->Field("depth.stereo.fuse_shared_variance", &depth.stereo.fuse_shared_variance);
  visitor->Field("depth.flight.baseline_m", &depth.flight.baseline_m);
  visitor->Field("depth.flight.min_baseline_m", &depth.flight.min_baseline_m);
  visitor->Field("depth.flight.min_sideways_share", &depth.flight.min_sideways_share);
  visitor->Field("depth.flight.min_range_m", &depth.flight.min_range_m);
  visitor->Field("depth.flight.history_s", &depth.flight.history_s);
  visitor->Field("map.whole_patrols", &config->map.whole_patrols);
  visitor->Field("map.archive_frame_interval_s", &config->map.archive_frame_interval_s);
}

// Loads `path` over the defaults in `config`: keys absent from the file keep
// their value; an unknown key, a value of the wrong type or an invalid
// combination fails with a message naming the file, the key and the line.
Status LoadConfig(const std::string& path, Config* config);

// Sets keys from the command line's "--set KEY=VALUE" (KEY as in the file, "place.max_log_nfa"), in order, over
// `config`: each is read as the file's key would be, and an unknown key fails naming the nearest known one.
Status ApplySettings(const std::vector<std::string>& settings, Config* config);

// The defaults, with `path` loaded over them unless it is empty and then `settings` (ApplySettings), checked
// (Config::IsValid).
Status LoadCheckedConfig(const std::string& path, const std::vector<std::string>& settings, Config* config);
inline Status LoadCheckedConfig(const std::string& path, Config* config) { return LoadCheckedConfig(path, {}, config); }

// The change stage's options as the configuration sets them: config.change, with the depth section's matching and
// baseline options copied into the route's motion stereo (change.route.depth matches route frames as depth.stereo
// and depth.flight say).
::patrolmap::change::ChangeOptions ChangeOptionsOf(const Config& config);

// The configuration as YAML (every key, nested sections).
std::string ConfigToYaml(const Config& config);

}  // namespace patrolmap::pipeline
