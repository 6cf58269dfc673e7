#include "patrolmap/flow/signal.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "patrolmap/core/status.h"

namespace patrolmap::flow {

WindowSmoother::WindowSmoother(int window, SmoothingMode mode) {
  PATROLMAP_CHECK(window >= 1);
  if (mode == SmoothingMode::kCentered) {
    behind_ = (window - 1) / 2;
    ahead_ = window - 1 - behind_;
  } else {
    behind_ = window - 1;
    ahead_ = 0;
  }
}

double WindowSmoother::MeanOver(std::size_t first, std::size_t last) const {
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = first; i <= last; ++i) {
    const double value = history_[i].raw_response;
    if (std::isnan(value)) continue;
    sum += value;
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

// Releases the oldest pending sample with the window that is available now.
void WindowSmoother::Release(std::vector<FlowSample>* released) {
  const std::size_t centre = released_in_history_;
  const std::size_t first = centre >= static_cast<std::size_t>(behind_) ? centre - behind_ : 0;
  const std::size_t last = std::min(history_.size() - 1, centre + static_cast<std::size_t>(ahead_));
  FlowSample sample = history_[centre];
  sample.smoothed_response = MeanOver(first, last);
  released->push_back(sample);
  ++released_in_history_;
  while (released_in_history_ > static_cast<std::size_t>(behind_)) {
    history_.pop_front();
    --released_in_history_;
  }
}

void WindowSmoother::Add(const FlowSample& sample, std::vector<FlowSample>* released) {
  history_.push_back(sample);
  while (history_.size() - released_in_history_ > static_cast<std::size_t>(ahead_)) Release(released);
}

void WindowSmoother::Finish(std::vector<FlowSample>* released) {
  while (released_in_history_ < history_.size()) Release(released);
}

ExtremumDetector::ExtremumDetector(const ExtremumOptions& options) : options_(options) {}

void ExtremumDetector::Confirm(ExtremumKind kind, std::vector<KeyLocation>* events) {
  const TimestampNs min_gap = SecondsToNs(options_.min_time_s);
  if (has_node_ && candidate_.timestamp_ns - last_node_ns_ < min_gap) return;
  KeyLocation event;
  event.node_index = next_node_index_++;
  event.timestamp_ns = candidate_.timestamp_ns;
  event.frame_index = candidate_.frame_index;
  event.response = candidate_.smoothed_response;
  event.kind = kind;
  events->push_back(event);
  has_node_ = true;
  last_node_ns_ = candidate_.timestamp_ns;
}

void ExtremumDetector::Add(const FlowSample& sample, std::vector<KeyLocation>* events) {
  const double value = sample.smoothed_response;
  if (std::isnan(value)) return;
  if (!has_reference_) {
    candidate_ = sample;
    has_reference_ = true;
    return;
  }
  const double change = options_.min_change;
  const double candidate = candidate_.smoothed_response;
  switch (trend_) {
    case Trend::kUnknown:
      if (value >= candidate + change)
        trend_ = Trend::kRising;
      else if (value <= candidate - change)
        trend_ = Trend::kFalling;
      else
        return;
      candidate_ = sample;
      return;
    case Trend::kRising:
      if (value > candidate) {
        candidate_ = sample;
      } else if (value <= candidate - change) {
        Confirm(ExtremumKind::kPeak, events);
        trend_ = Trend::kFalling;
        candidate_ = sample;
      }
      return;
    case Trend::kFalling:
      if (value < candidate) {
        candidate_ = sample;
      } else if (value >= candidate + change) {
        Confirm(ExtremumKind::kValley, events);
        trend_ = Trend::kRising;
        candidate_ = sample;
      }
      return;
  }
}

}  // namespace patrolmap::flow
