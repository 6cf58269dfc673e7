#include "patrolmap/depth/options.h"

#include "patrolmap/core/option_check.h"

namespace patrolmap::depth {

const char* ToString(DepthSource source) {
  switch (source) {
    case DepthSource::kAuto: return "auto";
    case DepthSource::kImages: return "images";
    case DepthSource::kStereo: return "stereo";
    case DepthSource::kFlight: return "flight";
    case DepthSource::kNone: return "none";
  }
  return "auto";
}

bool ParseDepthSource(const std::string& text, DepthSource* source) {
  for (DepthSource candidate :
       {DepthSource::kAuto, DepthSource::kImages, DepthSource::kStereo, DepthSource::kFlight, DepthSource::kNone}) {
    if (text == ToString(candidate)) return *source = candidate, true;
  }
  return false;
}

bool StereoOptions::IsValid(std::string* error) const {
  OptionCheck check(error);
  check.InRange("depth.stereo.num_disparities", num_disparities, 16, 512)
      .Holds("depth.stereo.num_disparities", num_disparities, num_disparities % 16 == 0, "must be a multiple of 16")
      .InRange("depth.stereo.block_size", block_size, 1, 21)
      .Holds("depth.stereo.block_size", block_size, block_size % 2 == 1, "must be odd")
      .InRange("depth.stereo.uniqueness_ratio", uniqueness_ratio, 0, 100)
      .InRange("depth.stereo.max_lr_difference", max_lr_difference, 0.0, 64.0)
      .InRange("depth.stereo.speckle_window", speckle_window, 0, 10000)
      .InRange("depth.stereo.speckle_range", speckle_range, 1, 64)
      .InRange("depth.stereo.edge_radius_px", edge_radius_px, 0, 16)
      .AboveAtMost("depth.stereo.edge_jump_px", edge_jump_px, 0.0, 512.0)
      .AboveAtMost("depth.stereo.rate_hz", rate_hz, 0.0, 1000.0)
      .AboveAtMost("depth.stereo.min_range_m", min_range_m, 0.0, 1000.0)
      .AboveAtMost("depth.stereo.max_range_m", max_range_m, 0.0, 1000.0)
      .Holds("depth.stereo.max_range_m", max_range_m, max_range_m > min_range_m,
             "must be above depth.stereo.min_range_m")
      .InRange("depth.stereo.disparity_sigma_px", disparity_sigma_px, 0.0, 16.0)
      .InRange("depth.stereo.fuse_frames", fuse_frames, 0, 16)
      .AboveAtMost("depth.stereo.fuse_gate_sigmas", fuse_gate_sigmas, 0.0, 10.0)
      .InRange("depth.stereo.fuse_shared_variance", fuse_shared_variance, 0.0, 1.0);
  return check.ok();
}

bool FlightDepthOptions::IsValid(std::string* error) const {
  OptionCheck check(error);
  check.AboveAtMost("depth.flight.baseline_m", baseline_m, 0.0, 100.0)
      .AboveAtMost("depth.flight.min_baseline_m", min_baseline_m, 0.0, 100.0)
      .Holds("depth.flight.baseline_m", baseline_m, baseline_m >= min_baseline_m,
             "must be at least depth.flight.min_baseline_m")
      .InRange("depth.flight.min_sideways_share", min_sideways_share, 0.0, 1.0)
      .AboveAtMost("depth.flight.min_range_m", min_range_m, 0.0, 1000.0)
      .AboveAtMost("depth.flight.history_s", history_s, 0.0, 60.0);
  return check.ok();
}

}  // namespace patrolmap::depth
