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

}  // namespace
}  // namespace patrolmap::flow
