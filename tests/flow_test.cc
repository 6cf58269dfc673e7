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

constexpr double kPi = 3.14159265358979323846;

TEST(Polar, FollowsEquationsOneAndTwo) {
  const PolarVector a = ToPolar({{10.0f, 20.0f}, {3.0f, 4.0f}});
  EXPECT_NEAR(a.theta, std::atan2(4.0, 3.0), 1e-6);
  EXPECT_NEAR(a.r, 10.0 * 0.6 + 20.0 * 0.8, 1e-4);
  EXPECT_NEAR(a.length, 5.0, 1e-6);
  const PolarVector left = ToPolar({{50.0f, 7.0f}, {-2.0f, 0.0f}});
  EXPECT_NEAR(std::abs(left.theta), kPi, 1e-6);
  EXPECT_NEAR(left.r, -50.0, 1e-4);
  EXPECT_NEAR(left.length, 2.0, 1e-6);
}

// Runs the voter over frames that each hold the given vectors; returns per frame whether vector 0 passed.
std::vector<int> VoteSequence(HysteresisVoter* voter, const std::vector<std::vector<PolarVector>>& frames) {
  std::vector<int> passed;
  std::vector<std::uint8_t> accepted;
  for (const auto& vectors : frames) {
    voter->Vote(vectors, &accepted);
    passed.push_back(vectors.empty() ? -1 : accepted[0]);
  }
  return passed;
}

// Table I's hysteresis, cell by cell (paper 002 §III-A): a cell is accepted once its vote reaches 3 and
// dropped when it falls under 2; a vector passes when the frames before it have accepted its cell.
TEST(HysteresisVoter, AcceptsAfterThreeVotesAndDropsUnderTwo) {
  const VotingOptions options;  // accept 3, reject 2 (Table I)
  const PolarVector v = ToPolar({{100.0f, 50.0f}, {-8.0f, 0.0f}});
  HysteresisVoter voter(options, 376, 240);
  // Votes after each frame: 1, 2, 3 (accepted), 4th frame passes; absent twice: 2 (kept), 1 (dropped);
  // present: not accepted before, vote 2; present: vote 3, accepted again; present: passes.
  EXPECT_EQ(VoteSequence(&voter, {{v}, {v}, {v}, {v}, {}, {}, {v}, {v}, {v}}),
            (std::vector<int>{0, 0, 0, 1, -1, -1, 0, 0, 1}));
  voter.Reset();
  // The hysteresis itself: absent once, the vote falls to 2 -- under accept, not under reject -- and the
  // cell's vectors pass again at once. Without it (dropping under accept) the 5th frame would not pass.
  EXPECT_EQ(VoteSequence(&voter, {{v}, {v}, {v}, {}, {v}}), (std::vector<int>{0, 0, 0, -1, 1}));
  // With reject = accept there is no band: the same sequence drops the cell on the miss.
  VotingOptions no_band = options;
  no_band.reject = 3;
  HysteresisVoter plain(no_band, 376, 240);
  EXPECT_EQ(VoteSequence(&plain, {{v}, {v}, {v}, {}, {v}}), (std::vector<int>{0, 0, 0, -1, 0}));
}

TEST(HysteresisVoter, RandomDirectionsAreNeverAccepted) {
  HysteresisVoter voter(VotingOptions{}, 376, 240);
  cv::RNG rng(7);
  std::vector<std::uint8_t> accepted;
  int total = 0;
  for (int frame = 0; frame < 50; ++frame) {
    std::vector<PolarVector> vectors;
    for (int i = 0; i < 5; ++i) {
      vectors.push_back(ToPolar(
          {{rng.uniform(0.f, 376.f), rng.uniform(0.f, 240.f)}, {rng.uniform(-5.f, 5.f), rng.uniform(-5.f, 5.f)}}));
    }
    total += voter.Vote(vectors, &accepted);
  }
  EXPECT_LE(total, 3);  // 250 scattered vectors over ~2,700 cells: chance repeats only
}

TEST(SceneFlowResponse, AveragesAcceptedQuantityInImageWidths) {
  std::vector<PolarVector> vectors(3);
  vectors[0].length = 10, vectors[1].length = 20, vectors[2].length = 30;
  vectors[0].r = 5, vectors[1].r = -7, vectors[2].r = 9;
  const std::vector<std::uint8_t> accepted = {1, 0, 1};
  EXPECT_DOUBLE_EQ(SceneFlowResponse(vectors, accepted, ResponseQuantity::kLength, 100), 0.2);
  EXPECT_DOUBLE_EQ(SceneFlowResponse(vectors, accepted, ResponseQuantity::kLineParameter, 100), 0.07);
  EXPECT_TRUE(std::isnan(SceneFlowResponse(vectors, {0, 0, 0}, ResponseQuantity::kLength, 100)));
}

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
    values.push_back(0.05 + 0.03 * std::sin(2 * kPi * t / 10.0) + 0.004 * std::sin(2 * kPi * t / 0.7));
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
  for (int i = 0; i <= 300; ++i) values.push_back(0.05 - 0.009 * std::cos(2 * kPi * i / 100.0));
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

TEST(EdgeSelection, CapIsSharedByTheGridCells) {
  cv::Mat edges(200, 200, CV_8UC1, cv::Scalar(255));
  EdgeOptions options;
  options.max_points = 100;
  options.grid_columns = 2;
  options.grid_rows = 2;
  options.border = 0;
  std::vector<cv::Point2f> points;
  SelectEdgePoints(edges, options, &points);
  ASSERT_EQ(points.size(), 100u);
  int top_left = 0;
  for (const cv::Point2f& p : points) top_left += p.x < 100 && p.y < 100;
  EXPECT_EQ(top_left, 25);
  // Edges only in one quadrant: that cell's share, spread down its rows.
  edges.setTo(0);
  edges(cv::Rect(0, 0, 100, 100)).setTo(255);
  SelectEdgePoints(edges, options, &points);
  ASSERT_EQ(points.size(), 25u);
  EXPECT_GT(points.back().y, 90.0f);
}

cv::Mat Texture(int seed) {
  cv::Mat image(240, 376, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
  return image;
}

TEST(EdgeFlowTracker, RecoversAKnownShift) {
  const cv::Mat first = Texture(3);
  cv::Mat second;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3.0, 0, 1, -2.0);
  cv::warpAffine(first, second, shift, first.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  EdgeFlowTracker tracker(EdgeOptions{}, TrackerOptions{});
  std::vector<FlowVector> vectors;
  tracker.Track(first, &vectors);
  EXPECT_TRUE(vectors.empty());
  tracker.Track(second, &vectors);
  ASSERT_GT(vectors.size(), 300u);
  std::vector<float> dx, dy;
  for (const FlowVector& v : vectors) dx.push_back(v.delta.x), dy.push_back(v.delta.y);
  std::nth_element(dx.begin(), dx.begin() + dx.size() / 2, dx.end());
  std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
  EXPECT_NEAR(dx[dx.size() / 2], 3.0, 0.05);
  EXPECT_NEAR(dy[dy.size() / 2], -2.0, 0.05);
}

// A periodic checkerboard (period 8 px): no structure survives at coarse pyramid levels, so a
// 14 px motion is ambiguous for LK unless the search starts near the answer.
cv::Mat Checkerboard(int offset) {
  cv::Mat image(240, 376, CV_8UC1);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) image.at<uchar>(y, x) = ((x + offset) / 4 + y / 4) % 2 ? 200 : 60;
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

float MedianDx(const std::vector<FlowVector>& vectors) {
  std::vector<float> dx;
  for (const FlowVector& v : vectors) dx.push_back(v.delta.x);
  std::nth_element(dx.begin(), dx.begin() + dx.size() / 2, dx.end());
  return dx[dx.size() / 2];
}

// Motion ramps up 2, 4, ..., 14 px per frame (a platform taking off): with prediction each search
// starts from the previous flow and stays on the true period; without it, 14 px locks onto an alias.
float FinalMedianShift(bool predict) {
  TrackerOptions tracker;
  tracker.predict_from_previous = predict;
  EdgeFlowTracker flow(EdgeOptions{}, tracker);
  std::vector<FlowVector> vectors;
  int offset = 0;
  flow.Track(Checkerboard(offset), &vectors);
  for (int shift = 2; shift <= 14; shift += 2) {
    offset += shift;
    flow.Track(Checkerboard(offset), &vectors);
  }
  return MedianDx(vectors);
}

TEST(EdgeFlowTracker, PredictionFollowsLargeMotionOnRepetitiveTexture) {
  EXPECT_NEAR(FinalMedianShift(true), -14.0f, 0.5f);
  EXPECT_GT(std::abs(FinalMedianShift(false) + 14.0f), 2.0f);  // the problem prediction solves
}

TEST(Gyro, IntegratesAConstantRate) {
  std::vector<ImuSample> samples;
  for (int i = 1; i <= 40; ++i) {
    ImuSample sample;
    sample.timestamp_ns = SecondsToNs(i * 0.005);
    sample.gyro = Eigen::Vector3d(0.0, 0.0, 0.5);
    samples.push_back(sample);
  }
  const Eigen::Matrix3d rotation = IntegrateGyro(samples, 0, SecondsToNs(0.2), Eigen::Matrix3d::Identity());
  const Eigen::AngleAxisd angle_axis(rotation);
  EXPECT_NEAR(angle_axis.angle(), 0.1, 1e-9);
  EXPECT_NEAR(angle_axis.axis().z(), 1.0, 1e-9);
  // Only (start, end] counts.
  EXPECT_NEAR(Eigen::AngleAxisd(IntegrateGyro(samples, SecondsToNs(0.1), SecondsToNs(0.2), Eigen::Matrix3d::Identity()))
                  .angle(),
              0.05, 1e-9);
}

TEST(Derotation, RemovesFlowOfAPureRotation) {
  const CameraIntrinsics camera{229.0, 229.0, 187.5, 119.5, 376, 240};
  const Eigen::Matrix3d earlier_from_later =
      Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  Eigen::Matrix3d k;
  k << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1;
  std::vector<FlowVector> vectors;
  for (float x = 20; x < 360; x += 40) {
    for (float y = 20; y < 230; y += 40) {
      const Eigen::Vector3d moved = k * earlier_from_later.transpose() * k.inverse() * Eigen::Vector3d(x, y, 1);
      vectors.push_back({{x, y}, {float(moved.x() / moved.z() - x), float(moved.y() / moved.z() - y)}});
    }
  }
  EXPECT_GT(std::abs(vectors[0].delta.x), 5.0f);
  DerotateFlow(camera, earlier_from_later, &vectors);
  for (const FlowVector& v : vectors) {
    EXPECT_NEAR(v.delta.x, 0.0, 1e-3);
    EXPECT_NEAR(v.delta.y, 0.0, 1e-3);
  }
}

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

TEST(KeyLocationDetectorDeathTest, InvalidOptionsAbort) {
  KeyLocationOptions options;
  options.smoothing.window_s = 0;
  EXPECT_DEATH(KeyLocationDetector(options, CameraContext{}), "flow.smoothing.window_s = 0");
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

TEST(KeyLocationDetector, FramesWithoutUsableImageAreCountedNotProcessed) {
  KeyLocationOptions options;
  KeyLocationDetector detector(options, CameraContext{});
  DetectorOutput output;
  Frame frame;
  frame.image = cv::Mat(1, 1, CV_8UC1, cv::Scalar(0));  // 1x1: nothing to track
  detector.Process(frame, &output);
  frame.index = 1;
  frame.image.release();
  detector.Process(frame, &output);
  EXPECT_EQ(detector.unusable_frames(), 2);
  EXPECT_EQ(detector.processed_frames(), 0);
}

TEST(KeyLocationDetector, StaticSceneGivesNoKeyLocation) {
  KeyLocationOptions options;
  options.frames.scale = 1.0;
  CameraContext context;
  context.frame_rate_hz = options.frames.rate_hz;  // every frame
  KeyLocationDetector detector(options, context);
  DetectorOutput output;
  Frame frame;
  const cv::Mat image = Texture(5);
  for (int i = 0; i < 120; ++i) {
    frame.index = i;
    frame.timestamp_ns = SecondsToNs(i / 6.0);
    frame.image = image;
    detector.Process(frame, &output);
  }
  detector.Finish(&output);
  EXPECT_EQ(output.samples.size(), 120u);
  EXPECT_TRUE(output.key_locations.empty());
  EXPECT_LT(output.samples[60].smoothed_response, 1e-3);
}

TEST(KeyLocationDetector, LengthResponseIsImageWidthsPerSecond) {
  KeyLocationOptions options;
  options.frames.scale = 1.0;
  options.smoothing.window_s = 0.2;  // one processed frame
  CameraContext context;
  context.frame_rate_hz = 5.0;
  options.frames.rate_hz = 5.0;  // every frame
  KeyLocationDetector detector(options, context);
  DetectorOutput output;
  const cv::Mat texture = Texture(9);
  Frame frame;
  for (int i = 0; i < 8; ++i) {
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -4.0 * i, 0, 1, 0);  // 4 px left per frame
    cv::warpAffine(texture, frame.image, shift, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    frame.index = i;
    frame.timestamp_ns = SecondsToNs(0.2 * i);
    detector.Process(frame, &output);
  }
  detector.Finish(&output);
  ASSERT_EQ(output.samples.size(), 8u);
  EXPECT_TRUE(std::isnan(output.samples[0].raw_response));
  EXPECT_NEAR(output.samples[7].raw_response, 4.0 / 376.0 / 0.2, 0.002);  // 0.0532 widths/s
  EXPECT_GT(output.samples[7].accepted_vectors, 300);
}

TEST(KeyLocationDetector, ProcessesEveryStepthFrameOnly) {
  KeyLocationOptions options;  // 6 processed frames per second: every 5th of 30 fps
  CameraContext context;
  context.frame_rate_hz = 30.0;
  KeyLocationDetector detector(options, context);
  DetectorOutput output;
  Frame frame;
  const cv::Mat image = Texture(5);
  int decoded = 0;
  for (int i = 0; i < 23; ++i) {
    frame.index = i;
    frame.image = detector.NeedsImage() ? image : cv::Mat();
    decoded += !frame.image.empty();
    detector.Process(frame, &output);
  }
  EXPECT_EQ(decoded, 5);  // frames 0, 5, 10, 15, 20
  EXPECT_EQ(detector.processed_frames(), 5);
}

}  // namespace
}  // namespace patrolmap::flow
