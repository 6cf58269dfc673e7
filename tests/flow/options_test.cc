#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "patrolmap/flow/options.h"

namespace patrolmap::flow {
namespace {

TEST(KeyLocationOptions, DefaultsAreTableOneAndChecksNameTheField) {
  KeyLocationOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error));
  EXPECT_EQ(options.voting.accept, 3);
  EXPECT_EQ(options.voting.reject, 2);
  EXPECT_DOUBLE_EQ(options.frames.rate_hz, 6.0);      // every 5th frame at 30 fps
  EXPECT_DOUBLE_EQ(options.smoothing.window_s, 5.0);  // Table I: 30 processed frames at 6 per second
  EXPECT_DOUBLE_EQ(options.extrema.min_change, 0.02);
  EXPECT_DOUBLE_EQ(options.extrema.min_time_s, 2.0);
  options.voting.reject = 4;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("reject"), std::string::npos);
}

// Durations are seconds: the paper's 30 fps / every 5th frame / 30-frame window, and the same times at
// the rates of a KITTI car log (10 Hz) and a EuRoC flight (20 Hz).
TEST(FrameTiming, DurationsInSecondsGiveTheFramesOfEachRate) {
  const KeyLocationOptions options;
  const FrameTiming paper = ResolveFrameTiming(options, 30.0);
  EXPECT_EQ(paper.step, 5);
  EXPECT_EQ(paper.window, 30);
  const FrameTiming kitti = ResolveFrameTiming(options, 10.0);
  EXPECT_EQ(kitti.step, 2);     // round(10 / 6)
  EXPECT_EQ(kitti.window, 25);  // 5 s at 5 processed frames per second
  const FrameTiming euroc = ResolveFrameTiming(options, 20.0);
  EXPECT_EQ(euroc.step, 3);
  EXPECT_EQ(euroc.window, 33);                                // 5 s at 6.67 per second
  const FrameTiming slow = ResolveFrameTiming(options, 1.0);  // a 1 Hz image collection: every image
  EXPECT_EQ(slow.step, 1);
  EXPECT_EQ(slow.window, 5);
  const FrameTiming unknown = ResolveFrameTiming(options, 0.0);
  EXPECT_EQ(unknown.step, 1);
  EXPECT_EQ(unknown.window, 30);
}

TEST(KeyLocationOptions, OutOfRangeValuesNameKeyValueAndRule) {
  KeyLocationOptions options;
  options.voting.max_votes = 300;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error, "flow.voting.max_votes = 300: must be an integer in [3, 100]");
  options = KeyLocationOptions();
  options.frames.scale = std::nan("");
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error, "flow.frames.scale = nan: must be a number in [0.05, 1]");
}

}  // namespace
}  // namespace patrolmap::flow
