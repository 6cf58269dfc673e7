#include "patrolmap/flow/polar_voting.h"

#include <algorithm>
#include <cmath>

#include "patrolmap/core/status.h"

namespace patrolmap::flow {

PolarVector ToPolar(const FlowVector& vector) {
  PolarVector polar;
  polar.theta = std::atan2(vector.delta.y, vector.delta.x);
  polar.r = vector.start.x * std::cos(polar.theta) + vector.start.y * std::sin(polar.theta);
  polar.length = std::hypot(vector.delta.x, vector.delta.y);
  return polar;
}

HysteresisVoter::HysteresisVoter(const VotingOptions& options, int image_width, int image_height) : options_(options) {
  PATROLMAP_CHECK(image_width > 0 && image_height > 0);
  PATROLMAP_CHECK(options.max_votes <= 255);
  // |r| never exceeds the distance of the far image corner from the origin.
  const float r_max = std::hypot(static_cast<float>(image_width), static_cast<float>(image_height));
  r_min_ = -r_max;
  r_bin_width_ = static_cast<float>(options.r_bin_fraction * image_width);
  r_bins_ = std::max(1, static_cast<int>(std::ceil(2.0f * r_max / r_bin_width_)));
  const std::size_t cells = static_cast<std::size_t>(options.theta_bins) * r_bins_;
  votes_.assign(cells, 0);
  accepted_.assign(cells, 0);
  observed_.assign(cells, 0);
}

void HysteresisVoter::Reset() {
  std::fill(votes_.begin(), votes_.end(), 0);
  std::fill(accepted_.begin(), accepted_.end(), 0);
}

int HysteresisVoter::CellOf(const PolarVector& vector) const {
  constexpr float kTwoPi = 6.28318530718f;
  const float turn = (vector.theta + 3.14159265359f) / kTwoPi;  // [0, 1]
  int theta_bin = static_cast<int>(turn * options_.theta_bins);
  theta_bin = std::clamp(theta_bin, 0, options_.theta_bins - 1);
  int r_bin = static_cast<int>((vector.r - r_min_) / r_bin_width_);
  r_bin = std::clamp(r_bin, 0, r_bins_ - 1);
  return theta_bin * r_bins_ + r_bin;
}

int HysteresisVoter::Vote(const std::vector<PolarVector>& vectors, std::vector<std::uint8_t>* accepted) {
  std::fill(observed_.begin(), observed_.end(), 0);
  cells_.resize(vectors.size());
  for (std::size_t i = 0; i < vectors.size(); ++i) {
    cells_[i] = CellOf(vectors[i]);
    observed_[cells_[i]] = 1;
  }
  // A vector passes when the earlier frames have accepted its cell: present over several consecutive frames,
  // and not yet discarded (its vote has not fallen under `reject` since). Then this frame votes.
  accepted->resize(vectors.size());
  int count = 0;
  for (std::size_t i = 0; i < vectors.size(); ++i) {
    (*accepted)[i] = accepted_[cells_[i]];
    count += (*accepted)[i];
  }
  UpdateCells();
  return count;
}

void HysteresisVoter::UpdateCells() {
  const int ceiling = options_.max_votes;
  for (std::size_t cell = 0; cell < votes_.size(); ++cell) {
    int vote = votes_[cell] + (observed_[cell] ? 1 : -1);
    vote = std::clamp(vote, 0, ceiling);
    votes_[cell] = static_cast<std::uint8_t>(vote);
    if (!accepted_[cell] && vote >= options_.accept)
      accepted_[cell] = 1;
    else if (accepted_[cell] && vote < options_.reject)
      accepted_[cell] = 0;
  }
}

}  // namespace patrolmap::flow
