#include "patrolmap/flow/options.h"

#include <algorithm>
#include <cmath>

#include "patrolmap/core/option_check.h"

namespace patrolmap::flow {
namespace {

void CheckFrames(const FrameOptions& frames, OptionCheck* check) {
  check->AboveAtMost("flow.frames.rate_hz", frames.rate_hz, 0.0, 1000.0)
      .InRange("flow.frames.scale", frames.scale, 0.05, 1.0);
}

void CheckEdges(const EdgeOptions& edges, OptionCheck* check) {
  check->InRange("flow.edges.canny_low", edges.canny_low, 0.0, 10000.0)
      .InRange("flow.edges.canny_high", edges.canny_high, edges.canny_low, 10000.0)
      .InRange("flow.edges.max_points", edges.max_points, 1, 100000)
      .InRange("flow.edges.grid_columns", edges.grid_columns, 1, 256)
      .InRange("flow.edges.grid_rows", edges.grid_rows, 1, 256)
      .InRange("flow.edges.border", edges.border, 0, 1000);
}

void CheckTracker(const TrackerOptions& tracker, OptionCheck* check) {
  check->InRange("flow.tracker.window_size", tracker.window_size, 3, 101)
      .InRange("flow.tracker.pyramid_levels", tracker.pyramid_levels, 0, 8)
      .InRange("flow.tracker.max_iterations", tracker.max_iterations, 1, 1000)
      .AboveAtMost("flow.tracker.epsilon", tracker.epsilon, 0.0, 10.0)
      .InRange("flow.tracker.min_eigen_threshold", tracker.min_eigen_threshold, 0.0, 1.0)
      .InRange("flow.tracker.max_forward_backward_px", tracker.max_forward_backward_px, 0.0, 1000.0);
}

void CheckVoting(const VotingOptions& voting, OptionCheck* check) {
  check->InRange("flow.voting.theta_bins", voting.theta_bins, 1, 3600)
      .AboveAtMost("flow.voting.r_bin_fraction", voting.r_bin_fraction, 0.0, 1.0)
      .InRange("flow.voting.accept", voting.accept, 1, 100)
      .InRange("flow.voting.reject", voting.reject, 0, voting.accept)
      .InRange("flow.voting.max_votes", voting.max_votes, voting.accept, 100);
}

void CheckResponse(const ResponseOptions& response, OptionCheck* check) {
  check->AboveAtMost("flow.response.reference_speed_mps", response.reference_speed_mps, 0.0, 1000.0)
      .AboveAtMost("flow.response.min_speed_mps", response.min_speed_mps, 0.0, 1000.0);
}

}  // namespace

bool KeyLocationOptions::IsValid(std::string* error) const {
  OptionCheck check(error);
  CheckFrames(frames, &check);
  CheckEdges(edges, &check);
  CheckTracker(tracker, &check);
  CheckVoting(voting, &check);
  CheckResponse(response, &check);
  check.AboveAtMost("flow.smoothing.window_s", smoothing.window_s, 0.0, 3600.0)
      .AboveAtMost("flow.extrema.min_change", extrema.min_change, 0.0, 1000.0)
      .InRange("flow.extrema.min_time_s", extrema.min_time_s, 0.0, 3600.0);
  return check.ok();
}

FrameTiming ResolveFrameTiming(const KeyLocationOptions& options, double frame_rate_hz) {
  FrameTiming timing;
  const bool known = std::isfinite(frame_rate_hz) && frame_rate_hz > 0.0;
  const double frames_per_step = known ? std::clamp(frame_rate_hz / options.frames.rate_hz, 1.0, 1e6) : 1.0;
  timing.step = static_cast<int>(std::lround(frames_per_step));
  timing.processed_rate_hz = known ? frame_rate_hz / timing.step : options.frames.rate_hz;
  const double window = std::round(options.smoothing.window_s * timing.processed_rate_hz);
  timing.window = static_cast<int>(std::clamp(window, 1.0, 1e6));
  return timing;
}

const char* ToString(ResponseQuantity quantity) {
  return quantity == ResponseQuantity::kLength ? "length" : "line_parameter";
}

const char* ToString(SmoothingMode mode) { return mode == SmoothingMode::kCentered ? "centered" : "causal"; }

bool ParseResponseQuantity(const std::string& text, ResponseQuantity* quantity) {
  if (text == "length")
    *quantity = ResponseQuantity::kLength;
  else if (text == "line_parameter")
    *quantity = ResponseQuantity::kLineParameter;
  else
    return false;
  return true;
}

bool ParseSmoothingMode(const std::string& text, SmoothingMode* mode) {
  if (text == "centered")
    *mode = SmoothingMode::kCentered;
  else if (text == "causal")
    *mode = SmoothingMode::kCausal;
  else
    return false;
  return true;
}

}  // namespace patrolmap::flow
