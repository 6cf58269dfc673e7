// Takes frames at a rate from a stream timed in nanoseconds (depth frames for the evidence grid, stereo pairs, route
// frames).
#pragma once

#include "patrolmap/core/types.h"

namespace patrolmap {

// Frames are due on a schedule of one every 1 / rate_hz seconds. Log times are rounded to the nanosecond (the third
// frame of a 30 Hz log is at 66666667 ns, the fifth at 133333333 ns) and real clocks jitter, so a frame up to a
// hundredth of a step early is due, and the schedule advances by whole steps from the time that was due, not from the
// frame taken: a 30 Hz log gives 15 frames a second at 15 Hz (not 10), and a 20 Hz log with jitter keeps 5 at 5 Hz.
// After a gap of more than a step the schedule starts again at the frame taken.
class RateGate {
 public:
  explicit RateGate(double rate_hz);
  bool Due(TimestampNs timestamp_ns) const;
  void Take(TimestampNs timestamp_ns);  // a due frame was used

 private:
  TimestampNs step_ns_;
  bool started_ = false;
  TimestampNs next_ns_ = 0;
};

}  // namespace patrolmap
