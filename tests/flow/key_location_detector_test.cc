#include <cmath>
#include <numeric>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "flow/fixtures.h"
#include "patrolmap/flow/edge_flow.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/flow/polar_voting.h"
#include "patrolmap/flow/signal.h"

namespace patrolmap::flow {
namespace {

using testing_fixtures::Texture;

TEST(KeyLocationDetectorDeathTest, InvalidOptionsAbort) {
  KeyLocationOptions options;
  options.smoothing.window_s = 0;
  EXPECT_DEATH(KeyLocationDetector(options, CameraContext{}), "flow.smoothing.window_s = 0");
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
