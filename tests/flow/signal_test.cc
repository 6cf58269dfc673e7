#include <cmath>
#include <numeric>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "patrolmap/flow/edge_flow.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/flow/polar_voting.h"
#include "patrolmap/flow/signal.h"

namespace patrolmap::flow {
namespace {

std::vector<FlowSample> Samples(const std::vector<double>& values, double rate_hz = 1.0) {
  std::vector<FlowSample> samples(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    samples[i].timestamp_ns = SecondsToNs(i / rate_hz);
    samples[i].frame_index = static_cast<std::int64_t>(i);
    samples[i].raw_response = values[i];
    samples[i].smoothed_response = values[i];
  }
  return samples;
}

std::vector<double> Smooth(const std::vector<double>& values, int window, SmoothingMode mode,
                           std::vector<int>* released_after = nullptr) {
  WindowSmoother smoother(window, mode);
  std::vector<FlowSample> released;
  for (const FlowSample& sample : Samples(values)) {
    smoother.Add(sample, &released);
    if (released_after) released_after->push_back(static_cast<int>(released.size()));
  }
  smoother.Finish(&released);
  std::vector<double> smoothed;
  for (const FlowSample& sample : released) smoothed.push_back(sample.smoothed_response);
  return smoothed;
}

TEST(WindowSmoother, CenteredWindowTruncatesAtTheEnds) {
  std::vector<int> released_after;
  const std::vector<double> smoothed = Smooth({1, 2, 3, 4, 5}, 3, SmoothingMode::kCentered, &released_after);
  EXPECT_EQ(smoothed, (std::vector<double>{1.5, 2, 3, 4, 4.5}));
  EXPECT_EQ(released_after, (std::vector<int>{0, 1, 2, 3, 4}));  // one sample late
}

TEST(WindowSmoother, CausalWindowLagsAndReleasesAtOnce) {
  std::vector<int> released_after;
  const std::vector<double> smoothed = Smooth({1, 2, 3, 4, 5}, 3, SmoothingMode::kCausal, &released_after);
  EXPECT_EQ(smoothed, (std::vector<double>{1, 1.5, 2, 3, 4}));
  EXPECT_EQ(released_after, (std::vector<int>{1, 2, 3, 4, 5}));
}

TEST(WindowSmoother, NaNSamplesAreLeftOut) {
  const double nan = std::nan("");
  const std::vector<double> smoothed = Smooth({1, nan, 3}, 3, SmoothingMode::kCentered);
  EXPECT_DOUBLE_EQ(smoothed[1], 2.0);
  EXPECT_TRUE(std::isnan(Smooth({nan, nan}, 1, SmoothingMode::kCentered)[0]));
}

TEST(WindowSmoother, PaperWindowCentresAStepOnItsMidpoint) {
  std::vector<double> step(100, 0.0);
  std::fill(step.begin() + 50, step.end(), 1.0);
  const std::vector<double> smoothed = Smooth(step, 30, SmoothingMode::kCentered);
  EXPECT_DOUBLE_EQ(smoothed[35], 1.0 / 30.0);  // window [21, 50] holds one 1
  EXPECT_DOUBLE_EQ(smoothed[49], 15.0 / 30.0);
  EXPECT_DOUBLE_EQ(smoothed[64], 1.0);
  const std::vector<double> causal = Smooth(step, 30, SmoothingMode::kCausal);
  EXPECT_DOUBLE_EQ(causal[64], 15.0 / 30.0);  // lag of (30 - 1) / 2 samples
}

std::vector<KeyLocation> Extrema(const std::vector<double>& values, double rate_hz, ExtremumOptions options) {
  ExtremumDetector detector(options);
  std::vector<KeyLocation> events;
  for (const FlowSample& sample : Samples(values, rate_hz)) detector.Add(sample, &events);
  return events;
}

TEST(ExtremumDetector, FindsEveryPeakAndValleyOfASineWithWiggles) {
  std::vector<double> values;
  for (int i = 0; i <= 300; ++i) {
    const double t = i / 10.0;
    values.push_back(0.05 + 0.03 * std::sin(2 * M_PI * t / 10.0) + 0.004 * std::sin(2 * M_PI * t / 0.7));
  }
  const std::vector<KeyLocation> events = Extrema(values, 10.0, {0.02, 2.0});
  ASSERT_EQ(events.size(), 6u);
  const double expected[] = {2.5, 7.5, 12.5, 17.5, 22.5, 27.5};
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_NEAR(NsToSeconds(events[i].timestamp_ns), expected[i], 0.4) << i;  // the wiggle moves them
    EXPECT_EQ(events[i].kind, i % 2 == 0 ? ExtremumKind::kPeak : ExtremumKind::kValley);
    EXPECT_EQ(events[i].node_index, static_cast<int>(i));
  }
}

TEST(ExtremumDetector, ChangesSmallerThanTheThresholdAreNotNodes) {
  std::vector<double> values;
  // Starts in a valley; peaks at 5, 15, 25 s, valleys at 10, 20 s (the one at 30 s is never confirmed).
  for (int i = 0; i <= 300; ++i) values.push_back(0.05 - 0.009 * std::cos(2 * M_PI * i / 100.0));
  EXPECT_TRUE(Extrema(values, 10.0, {0.02, 2.0}).empty());  // swing 0.018 < 0.02
  const std::vector<KeyLocation> events = Extrema(values, 10.0, {0.015, 2.0});
  ASSERT_EQ(events.size(), 5u);
  EXPECT_EQ(events[0].frame_index, 50);
  EXPECT_EQ(events[1].frame_index, 100);
}

// Table I's minimum change, exactly: a peak is confirmed once the signal has fallen the whole minimum
// change below it (0.02), not before (a fall of 0.015 held for 20 s confirms nothing).
TEST(ExtremumDetector, APeakIsConfirmedOnlyAfterTheWholeMinimumChange) {
  std::vector<double> values = {0.0, 0.05, 0.1};  // rising: the trend is set, 0.1 is the candidate peak
  values.insert(values.end(), 20, 0.085);         // 0.015 below the peak
  EXPECT_TRUE(Extrema(values, 1.0, {0.02, 0.0}).empty());
  values.push_back(0.0801);  // 0.0199 below
  EXPECT_TRUE(Extrema(values, 1.0, {0.02, 0.0}).empty());
  values.push_back(0.08);  // the full 0.02
  const std::vector<KeyLocation> events = Extrema(values, 1.0, {0.02, 0.0});
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ExtremumKind::kPeak);
  EXPECT_EQ(events[0].frame_index, 2);  // the peak's own sample, confirmed 22 samples later
  EXPECT_DOUBLE_EQ(events[0].response, 0.1);
}

TEST(ExtremumDetector, NodesCloserThanTheMinimumTimeAreDropped) {
  // Peak at 1 s, valley at 2 s, peak at 6 s, valley at 7 s (1 Hz samples).
  const std::vector<double> values = {0.0, 0.1, 0.0, 0.05, 0.08, 0.09, 0.1, 0.0, 0.1};
  const std::vector<KeyLocation> all = Extrema(values, 1.0, {0.05, 0.0});
  ASSERT_EQ(all.size(), 4u);
  const std::vector<KeyLocation> spaced = Extrema(values, 1.0, {0.05, 2.0});
  ASSERT_EQ(spaced.size(), 2u);
  EXPECT_EQ(spaced[0].frame_index, 1);
  EXPECT_EQ(spaced[1].frame_index, 6);
}

}  // namespace
}  // namespace patrolmap::flow
