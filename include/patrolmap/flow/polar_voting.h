// Flow vectors in polar form and hysteresis voting over them, paper 002 §III-A
// (equations 1-2, Table I).
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/types.hpp>

#include "patrolmap/flow/options.h"

namespace patrolmap::flow {

// A tracked point: where it was in the earlier frame and how far it moved [pixels].
struct FlowVector {
  cv::Point2f start;
  cv::Point2f delta;
};

// Equations 1-2: theta = atan2(dy, dx) in (-pi, pi] (the full direction; the
// paper's atan(dy/dx) cannot tell left from right), r = x1 cos(theta) + y1 sin(theta)
// with (x1, y1) the start in image coordinates (origin at the top-left pixel), and
// the vector length sqrt(dx^2 + dy^2) [pixels].
struct PolarVector {
  float theta = 0.0f;
  float r = 0.0f;
  float length = 0.0f;
};

PolarVector ToPolar(const FlowVector& vector);

// Votes for (theta, r) cells over consecutive frames (paper 002 §III-A: "only flow vectors present over
// several consecutive frames are accepted ... discarded again once [not] observed in a few frames and
// [the] vote falls under the minimum hysteresis threshold"). Each frame a cell that holds at least one
// vector gains a vote (up to max_votes), every other cell loses one. A cell becomes accepted when its
// vote reaches `accept` and stays accepted until its vote falls under `reject`. A vector passes when its
// cell was accepted by the frames before it, so with Table I's accept 3 / reject 2 a cell seen in 3
// frames passes its vectors from the 4th on, and a cell missed in one frame (vote 3 -> 2, still
// accepted) passes them again at once, while one missed twice (vote 1) must earn its votes anew.
class HysteresisVoter {
 public:
  // `image_width` and `image_height` fix the r range [pixels].
  HysteresisVoter(const VotingOptions& options, int image_width, int image_height);

  // Votes with this frame's vectors and sets accepted[i] for each vector.
  // Returns the number of accepted vectors.
  int Vote(const std::vector<PolarVector>& vectors, std::vector<std::uint8_t>* accepted);

  void Reset();
  int CellOf(const PolarVector& vector) const;
  int cell_count() const { return static_cast<int>(votes_.size()); }

 private:
  void UpdateCells();

  VotingOptions options_;
  float r_min_ = 0.0f;
  float r_bin_width_ = 1.0f;
  int r_bins_ = 1;
  std::vector<std::uint8_t> votes_;
  std::vector<std::uint8_t> accepted_;
  std::vector<std::uint8_t> observed_;
  std::vector<int> cells_;  // cell of each vector of the current frame
};

}  // namespace patrolmap::flow
