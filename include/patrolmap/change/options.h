// Options of the change stage (DESIGN.md, change; papers 000, 001, 003, 004).
// config/default.yaml mirrors these structs under `change:`.
#pragma once

#include <string>

#include "patrolmap/depth/options.h"

namespace patrolmap::change {

// Appearance: changed regions between two registered key frames.
struct AppearanceOptions {
  double ratio = 0.8;                   // descriptor ratio test for the registration matches
  double inlier_threshold_px = 3.0;     // homography RANSAC threshold [key-frame pixels]
  int min_inliers = 12;                 // fewer: the pair is not registered and not compared
  double blur_sigma_px = 1.0;           // Gaussian blur before differencing
  int search_radius_px = 2;             // each pixel takes the best match within this shift (parallax)
  double min_difference = 20.0;         // after global gain/offset compensation [grey levels], and ...
  double min_structure_change = 0.4;    // 1 - SSIM's contrast-structure term (gain and offset free) must exceed this
  double structure_sigma_px = 1.5;      // Gaussian window of that term
  int closing_px = 4;                   // changed pixels this close join one region (morphological closing)
  double min_area_fraction = 0.002;     // regions smaller than this share of the compared area are dropped, ...
  double min_side_fraction = 0.04;      // ... and so are regions thinner than this share of the image's shorter
                                        // side (seams at depth edges and the image border)
  double min_unmatched_share = 0.5;     // ... and so are regions with features of which fewer than this share lost
                                        // their match between the key frames (parallax, not change)
  int parallax_search_px = 8;           // ... and regions whose content the registered prior image shows, up to
  double max_shifted_similarity = 0.6;  // this far off, with a normalised cross-correlation above this, ...
  // ... and horizontally up to this far (at least parallax_search_px): the patrols' paths lie side by side, and
  // background a nearer edge hides in one frame shows beside that edge in the other.
  int horizontal_parallax_search_px = 24;
  // ... and regions within this far of where the registered prior frame ends inside the current one (0: kept).
  int edge_margin_px = 1;
  // Planes registered per pair: after the dominant homography, further ones are fitted to the matches none
  // before explains (each needs min_inliers), and each pixel is compared through the plane that registers it
  // best: a facade and the ground, or a nearer building, seen with parallax. 1: the dominant plane only.
  int max_planes = 1;
  // Also search each pixel's prior window in the current image, and require a region's content to be found
  // shifted both ways before it counts as parallax: finds objects that left as well as objects that came. Off:
  // a face lit in one flight and in shade in the other then gives regions too (BENCHMARKS.md, "Appearance along the
  // route").
  bool both_ways = false;
};

// Depth along the route (route_depth.h): each route frame with a pose is matched against the frames before and after
// it in its own patrol (motion stereo: one flight, so one light), and a compared pair's pixels also count as changed
// where one patrol's surface lies in the space the other patrol saw through.
struct RouteDepthOptions {
  bool enabled = true;        // needs poses both patrols place in one world frame (not GPS fixes)
  int num_disparities = 128;  // disparity search range [px], a multiple of 16
  // How the frames are matched and which neighbours are used: the configuration's depth.stereo options (block size,
  // matching noise, range) and depth.flight's baseline limits, which pipeline::ChangeOptionsOf copies here; not keys
  // of their own.
  depth::StereoOptions matching;
  depth::FlightDepthOptions baselines;
  // A surface counts as gone (or new) where the other patrol's depth along the ray lies beyond it by more than
  // this, and by more than sigmas times the two range errors.
  double min_change_m = 0.5;
  double sigmas = 3.0;
  // Where the visibility test marked at least parallax_min_marked_share of a region's box (the geometry changed)
  // and the current frame knows the depth of over parallax_known_share of it, the depth predicts where the
  // registered prior shows the region's content if nothing changed there (its parallax), and the shifted-copy test
  // looks for it only within parallax_slack_px of that place: a thing that moved a few pixels is no parallax.
  double parallax_min_marked_share = 0.02;
  double parallax_known_share = 0.3;
  int parallax_slack_px = 4;
};

// Appearance change along the route (RouteComparison): alignment of the current patrol's route frames to the
// prior patrol's, and voting over consecutive aligned pairs.
struct RouteCompareOptions {
  bool enabled = true;           // false: only the key frames of the places both patrols saw are compared
  double search_window_s = 4.0;  // a frame's partner is searched this far either side of its predicted time [s]
  int max_features = 800;        // SIFT features found per route frame
  int max_candidates = 6;        // prior frames registered per current frame: those most alike in a thumbnail
  int min_votes = 2;             // consecutive aligned pairs that must agree on a region for it to be reported
  double min_overlap = 0.3;      // agreeing regions overlap by this share of the smaller box
  RouteDepthOptions depth;
};

// Object map of one patrol (paper 000, with the 2D fallback of paper 001).
struct ObjectMapOptions {
  double centroid_gate_m = 1.0;     // candidates: map objects whose centroid is this close
  double pair_distance_m = 0.2;     // point-pair test: nearest-neighbour pairs closer than this agree
  double min_pair_fraction = 0.5;   // ... and at least this share of pairs must agree
  double point_voxel_m = 0.1;       // object points are kept one per voxel of this size
  double segment_depth_m = 0.8;     // depth pixels within this of the centroid's depth belong to the object
  int max_segment_samples = 400;    // depth pixels sampled per detection
  double min_box_iou = 0.3;         // 2D test: predicted and detected box must overlap this much
  double category_sigma_m = 0.5;    // 2D test: per-category prior, Gaussian on the centroid offset
  double vehicle_sigma_m = 1.0;     // ... wider for vehicles (labels containing "vehicle", "car", "truck")
  double min_category_prior = 0.1;  // 2D test: smallest prior probability accepted
  double merge_distance_m = 0.5;    // when the patrol ends, objects whose centroids are this close merge
  int min_detections = 3;           // objects seen fewer times stay unconfirmed: never reported themselves
  double max_range_m = 25.0;        // detections farther than this are ignored
  // Objects kept at most (memory stays bounded over long flights: a few kB each with their points); beyond,
  // the unconfirmed object seen longest ago is forgotten (with none, the object seen longest ago).
  int max_objects = 5000;
};

// State of every object between two patrols (papers 000, 001, 003).
struct ObjectDiffOptions {
  double match_distance_m = 1.0;       // persistent: same label, centroids this close [m]
  double max_move_m = 8.0;             // moved: the two positions at most this far apart (farther: removed + new)
  double physical_weight = 0.6;        // alpha of paper 003's weighted normalised distance; the appearance
                                       // distance weighs 1 - alpha (only the ratio orders the candidates)
  double max_visible_range_m = 20.0;   // visibility: a prior object farther than this is not covered by a view
  double min_visible_fraction = 0.5;   // visibility: at least this share of its projected box inside the image
  double min_expected_detections = 3;  // removed: the current views covering a prior object would have given at
                                       // least this many detections (its prior detections x covering views now /
                                       // covering views in its own patrol); fewer: unobserved
  double max_top_difference_m = 0.05;  // moved: the tops of the two objects (95th percentile of their points'
                                       // height) differ by at most this; objects stand on level ground
};

// Class-agnostic objects from changed geometry (paper 003's clustering of changed space; GeometryObjects).
struct GeometryObjectOptions {
  bool enabled = true;
  int cluster_gap_voxels = 1;  // changed voxels of one sign at most this many voxels apart (along each
                               // axis) form one cluster
  int min_voxels = 8;          // smaller clusters are no object
  // Each cluster grows into the whole object in its patrol's grid: the occupied voxels above the ground connected to
  // it (not past max_size_m). The ground is the median lowest occupied voxel of the columns within ground_search_m.
  bool complete_objects = true;
  double ground_search_m = 1.0;
  double min_surface_occupancy = 0.3;  // ... through voxels with two returns and at least this occupancy
  int ground_clearance_voxels = 1;  // ... and the growth stays this many voxels above it (rough ground, stereo noise)
  // A cluster none of whose voxels rises more than ground_clearance_voxels above the ground around it is a sheet of
  // ground seen a voxel off, no object. Only where a patrol's poses came from GPS, whose frame has z up
  // (ForPoseSources, evidence_grid.h).
  bool drop_ground_sheets = true;
  double footprint_gap_m = 0.4;        // clusters whose footprints come this close are one object (a side and a top
                                       // seen apart) [m]
  double max_size_m = 12.0;            // clusters longer than this horizontally are structure, not an object
  double max_move_m = 8.0;             // moved: a vanished and an appeared cluster at most this far apart [m]
  double max_top_difference_m = 0.15;  // ... whose tops differ by at most this (at 0.2 m voxels: the same top) [m]
  double min_shape_overlap = 0.5;      // ... and each of which, moved onto the other by the registration, has at
  double shape_tolerance_m = 0.3;      // least this share of its voxels within this distance of the other's [m]
  double shape_search_m = 0.6;         // ... at the best horizontal shift of up to this each way, in steps of a
                                       // voxel (at least shape_tolerance_m / 2), from centroid onto centroid (a
                                       // partial view pulls a centroid off the object's centre) [m]; 0 = centroids
                                       // only; at most 10 x shape_tolerance_m
  double physical_weight = 0.6;        // alpha of paper 003's weighted distance (physical, normalised); 1 - the
                                       // shape overlap weighs 1 - alpha
  double detection_margin_m = 0.5;     // a cluster whose box grown by this holds a detected object of its patrol,
                                       // or half of which lies in that object's box grown by this, is left to the
                                       // detector [m]
};

// Evidence grid of one patrol (paper 004).
struct EvidenceGridOptions {
  double voxel_size_m = 0.2;
  double max_range_m = 20.0;  // rays are traced this far; farther returns count as passes only
  int rays_per_row = 94;      // depth pixels traced per image row (every width/94-th pixel, and
                              // every as many rows): 94 is every 8th pixel at 752 px
  double rate_hz = 10.0;      // depth frames integrated per second of flight (stereo: see depth.stereo.rate_hz)
  // Uncertain depth (stereo) carves free space only up to this many range errors before a return.
  double free_space_sigmas = 2.0;
  // ... and marks a voxel hit only where its range error is at most this [m] (farther returns carve only).
  double max_hit_sigma_m = 0.5;
  // Memory of the grid's table at most, the copy made while it grows or sheds voxels included [MB]: 256 MB
  // hold 4.2 million voxels (16 bytes a slot; the largest table at most half used, smaller ones grow at three
  // quarters). When full, the least recently observed quarter of the voxels is dropped (EvidenceGrid); the
  // patrol record counts them.
  double memory_mb = 256.0;
};

// Geometry change between two evidence grids (paper 004).
struct GeometryDiffOptions {
  double min_occupancy_change = 0.45;  // |hits/(hits+passes) before - after| above this: changed
  double max_free_occupancy = 0.1;     // ... and in one patrol it must be free (a surface cut by the voxel's
                                       // edge fills it partly, by a share that changes with the view)
  int min_observations = 3;            // rays per voxel in each patrol; fewer: unobserved, never a change
  // No change where the free patrol's rays through a voxel number under this share of the occupied patrol's returns
  // there: a few rays through a surface the other patrol saw solid are outliers past an occluder (stereo matches
  // too far on a vehicle's side), not free space. 0 = off.
  double min_free_ratio = 0.2;
  int surface_tolerance_voxels = 1;  // no change where the free patrol has an occupied voxel this near
                                     // (a surface seen a voxel off: edges, corners); 0 = off
  bool vertical_tolerance = false;   // ... counting voxels above and below too (not only beside)
  double join_distance_m = 1.0;      // a changed voxel joins a region whose centroid is this close
  int min_region_voxels = 10;        // smaller regions are dropped as outliers, ...
  double min_region_width_m = 0.4;   // ... and so are narrower ones (a lone column of voxels at an edge)
  // ... and so are regions one voxel layer thick that lie on the ground around them (within one voxel): the ground
  // seen a voxel higher or lower (what correcting GPS poses to the nearest whole voxel leaves), not a change. A new
  // roof or lid seen from above, with the ground lower around it, stays. Only where a patrol's poses came from GPS
  // (ForPoseSources), whose frame has z up.
  bool drop_ground_sheets = true;
  // ... and so are regions holding both vanished and appeared voxels whose voxel centres spread across their main
  // horizontal axis by under this (standard deviation, in voxels): one voxel thick, a facade's edge seen a voxel off
  // from another angle, not a thing that came or left. 0 = off.
  double min_shift_thickness_voxels = 0.4;
  // ... and so are regions whose voxels all appeared or all vanished when, in at least min_capped_columns of their
  // columns, a voxel both patrols saw occupied stands at most cap_search_voxels above a changed one: the top of a
  // thing still there, whose lower part one patrol's stereo saw through (a plain or dark side). Only where z points
  // up (ForPoseSources: not with a --poses file). 0 = off.
  int min_capped_columns = 2;
  int cap_search_voxels = 3;
  // When more than this share of the surface voxels both patrols observed differ, the patrols' poses disagree
  // (GPS without RTK, another world frame): nothing is reported, and the report says why. 1 = never.
  double max_differing_share = 0.25;
};

// Frames kept along the route in the patrol record (RouteFrame): the change report's before and after
// pictures come from them. A frame every interval_s and every key frame, grey, JPEG. When the frames of a
// patrol pass memory_mb, every other one is dropped and the interval doubles, so a long flight keeps its
// whole route at a coarser spacing.
struct RouteFrameOptions {
  double interval_s = 1.0;  // flight time between kept frames [s]; 0: none kept
  int max_width = 376;      // wider frames are scaled down to this [px]
  int jpeg_quality = 80;    // 0-100
  double memory_mb = 16.0;  // a patrol's frames at most [MB] (in memory and in the map file)
};

// Aligning a new patrol's grid to the earlier patrol's before they are compared (grid_alignment.h).
struct GridAlignmentOptions {
  double max_shift_m = 2.0;  // the largest shift searched along each axis [m]; 0 = no alignment
  double min_gain = 0.2;     // the shift must overlap this share more occupied voxels than no shift
  // While flying (onboard), a shift is searched at a check whose share of differing surface voxels exceeds this,
  // until one is taken (again when the poses then disagree). Right poses measured at most 0.05.
  double min_differing_share = 0.05;
};

// Where a change seen in images stands (change_location.h).
struct ChangeLocationOptions {
  double min_depth_share = 0.3;    // a region is placed by its frame's depth when this share of its pixels know it
  double min_ray_angle_deg = 2.0;  // views triangulate a change when their rays open at least this wide [deg]
  double max_range_m = 60.0;       // no change is placed farther from the camera than this [m]
};

struct ChangeOptions {
  AppearanceOptions appearance;
  ObjectMapOptions object_map;
  ObjectDiffOptions objects;
  EvidenceGridOptions grid;
  GeometryDiffOptions geometry;
  GeometryObjectOptions geometry_objects;
  GridAlignmentOptions alignment;
  RouteFrameOptions route_frames;
  RouteCompareOptions route;
  ChangeLocationOptions location;
  // False with a message naming the first invalid option.
  bool IsValid(std::string* error) const;
};

}  // namespace patrolmap::change
