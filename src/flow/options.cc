#include "patrolmap/flow/options.h"

namespace patrolmap::flow {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

bool CheckFrames(const FrameOptions& frames, std::string* error) {
  if (frames.step < 1) return Fail(error, "flow.frames.step must be at least 1");
  if (!(frames.scale > 0.0 && frames.scale <= 1.0)) return Fail(error, "flow.frames.scale must be in (0, 1]");
  return true;
}

bool CheckEdges(const EdgeOptions& edges, std::string* error) {
  if (!(edges.canny_low >= 0.0 && edges.canny_high >= edges.canny_low)) {
    return Fail(error, "flow.edges: need 0 <= canny_low <= canny_high");
  }
  if (edges.max_points < 1) return Fail(error, "flow.edges.max_points must be at least 1");
  if (edges.grid_columns < 1 || edges.grid_rows < 1) return Fail(error, "flow.edges grid must be at least 1x1");
  if (edges.border < 0) return Fail(error, "flow.edges.border must not be negative");
  return true;
}

bool CheckTracker(const TrackerOptions& tracker, std::string* error) {
  if (tracker.window_size < 3) return Fail(error, "flow.tracker.window_size must be at least 3");
  if (tracker.pyramid_levels < 0) return Fail(error, "flow.tracker.pyramid_levels must not be negative");
  if (tracker.max_iterations < 1) return Fail(error, "flow.tracker.max_iterations must be at least 1");
  if (!(tracker.epsilon > 0.0)) return Fail(error, "flow.tracker.epsilon must be positive");
  if (!(tracker.min_eigen_threshold >= 0.0)) return Fail(error, "flow.tracker.min_eigen_threshold must not be negative");
  if (!(tracker.max_forward_backward_px >= 0.0)) {
    return Fail(error, "flow.tracker.max_forward_backward_px must not be negative");
  }
  return true;
}

bool CheckVoting(const VotingOptions& voting, std::string* error) {
  if (voting.theta_bins < 1) return Fail(error, "flow.voting.theta_bins must be at least 1");
  if (!(voting.r_bin_fraction > 0.0)) return Fail(error, "flow.voting.r_bin_fraction must be positive");
  if (voting.reject < 0 || voting.accept < voting.reject) {
    return Fail(error, "flow.voting: need 0 <= reject <= accept");
  }
  if (voting.max_votes < voting.accept) return Fail(error, "flow.voting.max_votes must be at least accept");
  return true;
}

bool CheckResponse(const ResponseOptions& response, std::string* error) {
  if (!(response.reference_speed_mps > 0.0)) return Fail(error, "flow.response.reference_speed_mps must be positive");
  if (!(response.min_speed_mps > 0.0)) return Fail(error, "flow.response.min_speed_mps must be positive");
  return true;
}

}  // namespace

bool KeyLocationOptions::IsValid(std::string* error) const {
  if (!CheckFrames(frames, error) || !CheckEdges(edges, error) || !CheckTracker(tracker, error) ||
      !CheckVoting(voting, error) || !CheckResponse(response, error)) {
    return false;
  }
  if (smoothing.window < 1) return Fail(error, "flow.smoothing.window must be at least 1");
  if (!(extrema.min_change > 0.0)) return Fail(error, "flow.extrema.min_change must be positive");
  if (!(extrema.min_time_s >= 0.0)) return Fail(error, "flow.extrema.min_time_s must not be negative");
  return true;
}

const char* ToString(ResponseQuantity quantity) {
  return quantity == ResponseQuantity::kLength ? "length" : "line_parameter";
}

const char* ToString(SmoothingMode mode) {
  return mode == SmoothingMode::kCentered ? "centered" : "causal";
}

bool ParseResponseQuantity(const std::string& text, ResponseQuantity* quantity) {
  if (text == "length") *quantity = ResponseQuantity::kLength;
  else if (text == "line_parameter") *quantity = ResponseQuantity::kLineParameter;
  else return false;
  return true;
}

bool ParseSmoothingMode(const std::string& text, SmoothingMode* mode) {
  if (text == "centered") *mode = SmoothingMode::kCentered;
  else if (text == "causal") *mode = SmoothingMode::kCausal;
  else return false;
  return true;
}

}  // namespace patrolmap::flow
