// Time-domain processing of the scene-flow response, paper 002 §III-A: a
// fixed-width window smoother and the peak/valley detector with the minimum
// change and minimum time thresholds of Table I. Both are streaming: they take
// one sample at a time, keep bounded memory and give the same result as a
// whole-signal computation.
#pragma once

#include <deque>
#include <vector>

#include "patrolmap/core/types.h"
#include "patrolmap/flow/options.h"

namespace patrolmap::flow {

// Box smoother of `window` samples over FlowSample::raw_response. NaN samples
// (frames with no accepted vector) are left out of the mean; a window with no
// valid sample yields NaN.
//  - kCentered: the value of sample c averages samples [c - (W-1)/2, c + W/2],
//    truncated at the ends of the log. Sample c is released once sample c + W/2
//    arrived (or at Finish), so results come W/2 samples late but without lag.
//  - kCausal: the value of sample k averages [k - W + 1, k] and is released at
//    once; the smoothed signal lags the raw one by (W - 1) / 2 samples.
class WindowSmoother {
 public:
  // `window` in samples (at least 1; FrameTiming converts the option's seconds).
  WindowSmoother(int window, SmoothingMode mode);

  // Adds a sample and appends every sample whose smoothed value is now final.
  void Add(const FlowSample& sample, std::vector<FlowSample>* released);
  // Releases the samples still held (end of log).
  void Finish(std::vector<FlowSample>* released);
  // Samples between a sample's arrival and its release.
  int latency_samples() const { return ahead_; }

 private:
  double MeanOver(std::size_t first, std::size_t last) const;
  void Release(std::vector<FlowSample>* released);

  int behind_ = 0;                  // samples before the centre in a full window
  int ahead_ = 0;                   // samples after the centre in a full window
  std::deque<FlowSample> history_;  // last behind_ samples already released, then pending ones
  std::size_t released_in_history_ = 0;
};

// Peak/valley detector (a zig-zag with threshold min_change): a peak is
// confirmed when the signal has fallen min_change below it, a valley when it
// has risen min_change above it, so consecutive extrema differ by at least
// min_change. The first sample is the initial reference and is never reported.
// A confirmed extremum becomes a key location when it lies at least min_time_s
// after the previous key location; otherwise it only moves the reference.
class ExtremumDetector {
 public:
  explicit ExtremumDetector(const ExtremumOptions& options);

  // Adds a smoothed sample (NaN is ignored); appends a key location when one is confirmed.
  void Add(const FlowSample& sample, std::vector<KeyLocation>* events);

 private:
  enum class Trend { kUnknown, kRising, kFalling };
  void Confirm(ExtremumKind kind, std::vector<KeyLocation>* events);

  ExtremumOptions options_;
  Trend trend_ = Trend::kUnknown;
  bool has_reference_ = false;
  FlowSample candidate_;  // the reference while trend_ is kUnknown
  bool has_node_ = false;
  TimestampNs last_node_ns_ = 0;
  int next_node_index_ = 0;
};

}  // namespace patrolmap::flow
