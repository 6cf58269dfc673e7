// The frames a patrol keeps along its route (change.route_frames; PatrolRecord::route): a frame every
// interval_s of flight and every key frame, grey, scaled down to max_width and stored as JPEG. The change
// report takes its before and after pictures from them.
//
// The frame thread decides which frames are due and scales them (Due, Scale); the change thread encodes and
// keeps them (Add). Past memory_mb every other interval frame is dropped and the interval doubles, so a long
// flight keeps its whole route at a coarser spacing; key frames stay. Which frames are kept depends on the
// order of Add() alone: one thread or two, the strip is the same.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/rate_gate.h"

namespace patrolmap::pipeline {

class RouteStrip {
 public:
  explicit RouteStrip(const change::RouteFrameOptions& options);

  // Frame thread: whether an interval frame is due at `timestamp_ns` (false when frames are not kept); a due
  // frame moves the next one on.
  bool Due(TimestampNs timestamp_ns);
  // Frame thread: whether the frame after one at `last_ns` (frames `spacing_ns` apart) may be due, so its
  // colour image is worth decoding.
  bool DueSoon(TimestampNs last_ns, TimestampNs spacing_ns) const;
  // Frame thread: `image` (grey or BGR) scaled down to max_width (a copy either way: the caller's buffer is reused).
  void Scale(const cv::Mat& image, cv::Mat* scaled) const;

  // Change thread: keeps `frame` with `image` (scaled) as JPEG; key frames are never thinned out.
  void Add(RouteFrame frame, const cv::Mat& image, bool key_frame);
  // Change thread, at the end: the frames in time order.
  std::vector<RouteFrame> Take();

  long long dropped() const { return dropped_; }  // frames not kept because key frames alone filled memory_mb
  int thinnings() const { return thinnings_; }    // times the interval doubled

 private:
  void Thin();

  change::RouteFrameOptions options_;
  RateGate gate_;  // frame thread: one frame every interval_s
  // Change thread:
  std::vector<RouteFrame> frames_;
  std::vector<long long> candidate_;  // per frame: its number among the interval frames; -1 for key frames
  long long candidates_ = 0;
  int thinnings_ = 0;
  std::size_t bytes_ = 0;
  long long dropped_ = 0;
  std::vector<int> encode_parameters_;
};

}  // namespace patrolmap::pipeline
