// Options of the depth stage (DESIGN.md, depth): where the change layer's depth comes from, and how a stereo
// pair is matched.
#pragma once

#include <string>

namespace patrolmap::depth {

// Which depth the change layer uses when a log has more than one.
enum class DepthSource {
  kAuto,    // depth0/ images when the log has them, else its stereo pair, else the flight's own frames
  kImages,  // depth0/ images only
  kStereo,  // the stereo pair only (cam0 + cam1)
  kFlight,  // motion stereo between frames of the flight (FlightDepth), with poses from a state estimate
  kNone,    // no depth: objects from detections without depth, no geometry
};

const char* ToString(DepthSource source);
bool ParseDepthSource(const std::string& text, DepthSource* source);

struct StereoOptions {
  int num_disparities = 64;        // disparity search range [px], a multiple of 16: the nearest depth is
                                   // f * b / num_disparities
  int block_size = 5;              // matched block side [px], odd
  int uniqueness_ratio = 30;       // the best cost must beat the second best by this percentage
  bool lr_check = true;            // left-right consistency check (matches the pair a second time, mirrored)
  double max_lr_difference = 0.5;  // ... the disparities of the two views may differ this much [px]
  int speckle_window = 400;        // disparity blobs smaller than this are removed [px]; 0: no speckle filter
  int speckle_range = 2;           // ... a blob's disparities vary at most this much [px]
  // Disparities within edge_radius_px of a jump are left unknown: where the window of that radius holds
  // disparities differing by more than edge_jump_px, SGBM's aggregation mixes the two surfaces and puts
  // returns into the free space between them. 0: off. BENCHMARKS.md, "Stereo depth".
  int edge_radius_px = 2;
  double edge_jump_px = 2.0;
  bool full_paths = false;  // 8 path directions (slower) instead of OpenCV's 3-way approximation
  // SGBM's sub-pixel fit pulls disparities towards whole pixels. When on, the pair is matched twice, with the
  // right image shifted by +quarter and -quarter of a pixel, and the two disparities (half a pixel apart in
  // their fraction, so their pull is opposite) are averaged; where they disagree by more than
  // max_lr_difference the disparity is left unknown. Costs one more matching per pair. BENCHMARKS.md.
  bool cancel_pixel_locking = false;
  // The pair is matched a second time at half the resolution with the same disparity range, which reaches half as
  // near (f * b / (2 num_disparities)) for about a quarter of the cost; where its disparity, doubled, lies beyond
  // the full resolution's range it stands in for it. Surfaces beside the path nearer than f * b / num_disparities
  // then get depth. BENCHMARKS.md, "Stereo depth".
  bool near_pass = false;
  // Stereo pairs matched per second of flight. The grid integrates depth at change.grid.rate_hz, so a pair is matched
  // at the lower of the two rates: matching costs far more than reading a depth image (BENCHMARKS.md, "Stereo depth").
  double rate_hz = 5.0;
  double min_range_m = 0.3;  // depths outside [min_range_m, max_range_m] are left unknown
  double max_range_m = 30.0;
  double disparity_sigma_px = 0.5;  // matching noise for RangeSigma [px]
  // Each depth frame at the grid's rate is fused with this many frames before it (DepthFusion): where they agree
  // within fuse_gate_sigmas combined range errors the depths are averaged, and the range error falls with the
  // square root of the views, but only on the share 1 - fuse_shared_variance of its variance: frames seeing a surface
  // from nearly the same distance share part of their matching error. 0: off. BENCHMARKS.md, "Stereo depth".
  int fuse_frames = 4;
  double fuse_gate_sigmas = 2.0;
  double fuse_shared_variance = 0.3;
  bool IsValid(std::string* error) const;
};

// Depth from the flight (depth/motion_stereo.h, FlightDepth): each frame the grid takes is matched, with
// depth.stereo's options, against the earlier frame whose baseline across the optical axis comes nearest
// baseline_m. The range error at depth z is z^2 * disparity_sigma_px / (f * baseline), so a longer baseline ranges
// farther surfaces, at the cost of nearer ones (nothing nearer than f * b / num_disparities is matched) and of views
// that differ more. Needs camera poses from a state estimate: GPS fixes are metres off.
struct FlightDepthOptions {
  double baseline_m = 2.0;          // the baseline sought [m]
  double min_baseline_m = 0.3;      // no earlier frame nearer than this is matched [m]
  double min_sideways_share = 0.7;  // ... nor one whose baseline runs less than this share across the optical axis
  // Each pair's disparity range reaches this near: f * baseline / min_range_m pixels (a multiple of 16, at most 512),
  // so a longer baseline is searched wider instead of matching near surfaces beyond its range wrongly [m].
  double min_range_m = 3.5;
  double history_s = 3.0;  // earlier frames are kept this long [s]
  bool IsValid(std::string* error) const;
};

struct DepthOptions {
  DepthSource source = DepthSource::kAuto;
  StereoOptions stereo;
  FlightDepthOptions flight;
  bool IsValid(std::string* error) const { return stereo.IsValid(error) && flight.IsValid(error); }
};

}  // namespace patrolmap::depth
