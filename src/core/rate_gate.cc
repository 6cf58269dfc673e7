#include "patrolmap/core/rate_gate.h"

#include <algorithm>

namespace patrolmap {

RateGate::RateGate(double rate_hz) : step_ns_(std::max<TimestampNs>(1, SecondsToNs(1.0 / rate_hz))) {}

// Up to a hundredth of a step early counts as due.
bool RateGate::Due(TimestampNs timestamp_ns) const { return !started_ || timestamp_ns >= next_ns_ - step_ns_ / 100; }

void RateGate::Take(TimestampNs timestamp_ns) {
  const bool on_schedule = started_ && timestamp_ns < next_ns_ + step_ns_;
  next_ns_ = (on_schedule ? next_ns_ : timestamp_ns) + step_ns_;
  started_ = true;
}

}  // namespace patrolmap
