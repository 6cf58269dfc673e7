// The depth stage: stereo matching against Middlebury's true disparity (Debian's opencv-doc), stereo depth
// of a synthetic pair whose geometry is known exactly, depth from the flight's own frames, the fusion of depth frames
// along a flight, and the lens.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/depth/fusion.h"
#include "patrolmap/depth/lens.h"
#include "patrolmap/depth/motion_stereo.h"
#include "patrolmap/depth/stereo.h"

namespace patrolmap::depth {
namespace {

const std::string kOpencvData = "/usr/share/doc/opencv-doc/examples/data";

struct DisparityScore {
  double within_1px = 0.0, within_3px = 0.0;  // of the pixels with a true disparity
  double density = 0.0;                       // share of them that got a disparity
};

DisparityScore Score(const cv::Mat& disparity, const cv::Mat& truth) {
  int known = 0, matched = 0, near1 = 0, near3 = 0;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      const int t = truth.at<std::uint8_t>(y, x);
      if (t == 0) continue;  // unknown in the truth
      ++known;
      const float d = disparity.at<float>(y, x);
      if (d < 0) continue;
      ++matched;
      near1 += std::abs(d - t) <= 1.0;
      near3 += std::abs(d - t) <= 3.0;
    }
  }
  return {static_cast<double>(near1) / known, static_cast<double>(near3) / known, static_cast<double>(matched) / known};
}

// Middlebury "Aloe" (full size, 1282x1110, true disparity up to 211 px; empty when opencv-doc is missing).
struct Aloe {
  const cv::Mat left = cv::imread(kOpencvData + "/aloeL.jpg", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(kOpencvData + "/aloeR.jpg", cv::IMREAD_GRAYSCALE);
  const cv::Mat truth = cv::imread(kOpencvData + "/aloeGT.png", cv::IMREAD_GRAYSCALE);
};

// The defaults with Aloe's disparity range (up to 211 px).
StereoOptions AloeOptions() {
  StereoOptions options;
  options.num_disparities = 256;
  return options;
}

// Pixels without a disparity count as wrong.
TEST(StereoMatching, MiddleburyAloeAgreesWithTheTrueDisparity) {
  const Aloe aloe;
  if (aloe.truth.empty()) GTEST_SKIP() << "opencv-doc not installed";
  const StereoOptions options = AloeOptions();
  cv::Mat disparity;
  ComputeDisparity(aloe.left, aloe.right, options, &disparity);
  const DisparityScore score = Score(disparity, aloe.truth);
  std::printf("aloe: %.3f within 1 px, %.3f within 3 px, %.3f matched\n", score.within_1px, score.within_3px,
              score.density);
  // Measured with the defaults: 0.737 within 1 px, 0.753 within 3 px, 0.756 matched (0.975 of the matched
  // within 1 px); without dropping depth edges 0.756, 0.775, 0.779 (0.970).
  EXPECT_GE(score.within_1px, 0.72);
  EXPECT_GE(score.within_3px, 0.74);
  EXPECT_GE(score.within_1px / score.density, 0.95);
}

// Without the left-right check more pixels get a disparity, and more of them are wrong (with permissive
// uniqueness and speckle settings, where the check has most to remove; depth edges kept, since dropping them
// removes many of the same errors).
TEST(StereoMatching, TheLeftRightCheckKeepsTheRightDisparities) {
  const Aloe aloe;
  if (aloe.truth.empty()) GTEST_SKIP() << "opencv-doc not installed";
  StereoOptions options = AloeOptions();
  options.edge_radius_px = 0;
  options.uniqueness_ratio = 10;
  options.speckle_window = 100;
  cv::Mat checked, unchecked;
  ComputeDisparity(aloe.left, aloe.right, options, &checked);
  options.lr_check = false;
  ComputeDisparity(aloe.left, aloe.right, options, &unchecked);
  const DisparityScore with = Score(checked, aloe.truth), without = Score(unchecked, aloe.truth);
  EXPECT_GT(without.density, with.density);
  EXPECT_GT(with.within_1px / with.density, without.within_1px / without.density + 0.01);
}

// Dropping the disparities next to depth edges (where SGBM's aggregation mixes the two surfaces) removes a
// share of the gross errors and little else. Measured on Aloe: gross errors (over 3 px) 0.50 % of the matched
// pixels without, 0.38 % with radius 2 and jump 2 px; 0.779 of the pixels matched without, 0.756 with.
TEST(StereoMatching, DroppingDepthEdgesRemovesGrossErrors) {
  const Aloe aloe;
  if (aloe.truth.empty()) GTEST_SKIP() << "opencv-doc not installed";
  StereoOptions options = AloeOptions();
  options.edge_radius_px = 0;
  cv::Mat kept, dropped;
  ComputeDisparity(aloe.left, aloe.right, options, &kept);
  options.edge_radius_px = 2;
  options.edge_jump_px = 2.0;
  ComputeDisparity(aloe.left, aloe.right, options, &dropped);
  const DisparityScore with = Score(dropped, aloe.truth), without = Score(kept, aloe.truth);
  const double gross_with = 1.0 - with.within_3px / with.density;
  const double gross_without = 1.0 - without.within_3px / without.density;
  EXPECT_LT(gross_with, 0.85 * gross_without);
  EXPECT_GT(with.density, without.density - 0.04);
  // Only disparities are dropped, none is changed.
  for (int y = 0; y < dropped.rows; ++y) {
    for (int x = 0; x < dropped.cols; ++x) {
      if (dropped.at<float>(y, x) < 0) continue;
      ASSERT_EQ(dropped.at<float>(y, x), kept.at<float>(y, x)) << x << "," << y;
    }
  }
}

// A fronto-parallel textured pair whose disparity is `disparity` px, fractions included: a smooth random
// texture drawn 8 times finer and averaged down, so each view is the same band-limited picture, shifted.
void ShiftedPair(double disparity, cv::Mat* left, cv::Mat* right) {
  constexpr int kFine = 8, kWidth = 240, kHeight = 160, kMargin = 40;
  cv::RNG rng(7);
  cv::Mat fine((kHeight + 2) * kFine, (kWidth + kMargin) * kFine, CV_32F);
  rng.fill(fine, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(fine, fine, cv::Size(), 2.0 * kFine);
  cv::normalize(fine, fine, 0.0, 255.0, cv::NORM_MINMAX);
  const int shift = static_cast<int>(std::lround(disparity * kFine));
  const auto view = [&](int offset, cv::Mat* image) {
    cv::Mat small;
    cv::resize(fine(cv::Rect(offset, 0, kWidth * kFine, kHeight * kFine)), small, cv::Size(kWidth, kHeight), 0, 0,
               cv::INTER_AREA);
    small.convertTo(*image, CV_8U);
  };
  view(0, left);
  view(shift, right);
}

// The mean error of the disparities found on a shifted pair, and how many were found.
double MeanError(const cv::Mat& left, const cv::Mat& right, double truth, const StereoOptions& options, int* found) {
  cv::Mat disparity;
  ComputeDisparity(left, right, options, &disparity);
  double sum = 0.0;
  *found = 0;
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 64; x < disparity.cols; ++x) {  // SGBM's first columns see what the right view does not
      const float d = disparity.at<float>(y, x);
      if (d < 0) continue;
      sum += d - truth;
      ++*found;
    }
  }
  return *found > 0 ? sum / *found : 0.0;
}

// SGBM's sub-pixel fit pulls disparities towards whole pixels; matching with the right view shifted by a quarter
// pixel both ways and averaging cancels most of that pull, at every fraction.
TEST(StereoMatching, CancellingPixelLockingTakesTheBiasOutOfFractionalDisparities) {
  StereoOptions options;
  double worst_plain = 0.0, worst_cancelled = 0.0;
  for (int eighth = 0; eighth < 8; ++eighth) {
    const double truth = 20.0 + eighth / 8.0;
    cv::Mat left, right;
    ShiftedPair(truth, &left, &right);
    int found_plain = 0, found_cancelled = 0;
    options.cancel_pixel_locking = false;
    const double plain = MeanError(left, right, truth, options, &found_plain);
    options.cancel_pixel_locking = true;
    const double cancelled = MeanError(left, right, truth, options, &found_cancelled);
    std::printf("disparity %.3f: mean error %+.3f px plain (%d), %+.3f px cancelled (%d)\n", truth, plain, found_plain,
                cancelled, found_cancelled);
    worst_plain = std::max(worst_plain, std::abs(plain));
    worst_cancelled = std::max(worst_cancelled, std::abs(cancelled));
    EXPECT_GT(found_cancelled, 0.8 * found_plain) << truth;
  }
  EXPECT_LT(worst_cancelled, 0.5 * worst_plain);
}

// A textured wall 8 m in front of a side-by-side pair (f = 400 px, b = 0.5 m): disparity 25 px.
struct WallPair {
  StereoCalibration calibration;
  cv::Mat left, right;
};

// A textured wall facing a pair 0.5 m apart (f = 400 px) with `disparity` pixels between the views: at
// 200 / disparity metres (25 px: 8 m).
WallPair Wall(int disparity = 25) {
  WallPair pair;
  const CameraIntrinsics camera{400.0, 400.0, 188.0, 120.0, 376, 240};
  pair.calibration.left = pair.calibration.right = camera;
  pair.calibration.right_from_left_translation = Eigen::Vector3d(-0.5, 0.0, 0.0);
  cv::Mat texture(240, 376 + disparity, CV_8UC1);
  cv::randu(texture, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  pair.left = texture.colRange(0, 376).clone();
  pair.right = texture.colRange(disparity, 376 + disparity).clone();
  return pair;
}

// Known pixels of `depth`, and those within `tolerance` of `z`.
std::pair<int, int> KnownAndAt(const cv::Mat& depth, double z, double tolerance) {
  int known = 0, at = 0;
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float value = depth.at<float>(y, x);
      if (value <= 0) continue;
      ++known;
      at += std::abs(value - z) < tolerance;
    }
  }
  return {known, at};
}

TEST(StereoDepth, AWallAtKnownDepthComesOutAtThatDepth) {
  const WallPair pair = Wall();
  std::unique_ptr<StereoDepth> stereo;
  ASSERT_TRUE(StereoDepth::Create(pair.calibration, StereoOptions(), &stereo).ok());
  EXPECT_NEAR(stereo->baseline_m(), 0.5, 1e-9);
  cv::Mat depth;
  ASSERT_TRUE(stereo->Compute(pair.left, pair.right, &depth).ok());
  ASSERT_EQ(depth.type(), CV_32FC1);
  ASSERT_EQ(depth.size(), pair.left.size());
  const auto [known, right_depth] = KnownAndAt(depth, 8.0, 0.08);
  // The first 25 columns see wall the right camera does not.
  EXPECT_GT(known, 0.85 * (376 - 25) * 240);
  EXPECT_GT(right_depth, 0.98 * known);
  EXPECT_NEAR(stereo->RangeSigma(8.0), 64.0 * 0.5 / (400.0 * 0.5), 1e-9);
  EXPECT_NEAR(stereo->DepthWithin(stereo->RangeSigma(8.0)), 8.0, 1e-9);
  EXPECT_NEAR(stereo->DepthWithin(0.5), std::sqrt(0.5 * 400.0 * 0.5 / 0.5), 1e-9);  // 0.5 m of error at 14.1 m
}

// The disparity range sets the nearest depth, f * b / num_disparities (what the run says at its start): a wall
// 2.5 m ahead (80 px) is beyond 64 disparities (3.1 m) and gets no depth; it comes out at 2.5 m with 96 (2.1 m),
// and with 64 and the near pass at half resolution (1.6 m).
TEST(StereoDepth, NothingNearerThanTheDisparityRangeReachesIsMatched) {
  const WallPair pair = Wall(80);
  // Known pixels, and those at the wall's 2.5 m, with `options`, whose nearest depth must be `nearest`.
  const auto known_and_at_wall = [&pair](const StereoOptions& options, double nearest) {
    std::unique_ptr<StereoDepth> stereo;
    cv::Mat depth;
    EXPECT_TRUE(StereoDepth::Create(pair.calibration, options, &stereo).ok());
    EXPECT_NEAR(stereo->NearestDepth(), nearest, 1e-9);
    EXPECT_TRUE(stereo->Compute(pair.left, pair.right, &depth).ok());
    return KnownAndAt(depth, 2.5, 0.05);
  };
  StereoOptions options;
  const auto [known_64, at_64] = known_and_at_wall(options, 400.0 * 0.5 / 64);
  EXPECT_LT(at_64, 0.01 * 376 * 240);
  EXPECT_LT(known_64, 0.05 * 376 * 240);  // no wrong depth in its place either

  options.num_disparities = 96;
  const auto [known_96, at_96] = known_and_at_wall(options, 400.0 * 0.5 / 96);
  EXPECT_GT(at_96, 0.8 * (376 - 80) * 240);
  EXPECT_GT(at_96, 0.98 * known_96);

  options.num_disparities = 64;
  options.near_pass = true;
  const auto [known_near, at_near] = known_and_at_wall(options, 400.0 * 0.5 / 128);
  EXPECT_GT(at_near, 0.8 * (376 - 80) * 240);
  EXPECT_GT(at_near, 0.98 * known_near);
}

// The near pass leaves what the full resolution reaches as it was: the wall 8 m ahead keeps its depth to the pixel.
TEST(StereoDepth, TheNearPassLeavesDepthWithinTheRangeAlone) {
  const WallPair pair = Wall();
  StereoOptions options;
  std::unique_ptr<StereoDepth> stereo;
  cv::Mat full, with_near;
  ASSERT_TRUE(StereoDepth::Create(pair.calibration, options, &stereo).ok());
  ASSERT_TRUE(stereo->Compute(pair.left, pair.right, &full).ok());
  options.near_pass = true;
  ASSERT_TRUE(StereoDepth::Create(pair.calibration, options, &stereo).ok());
  ASSERT_TRUE(stereo->Compute(pair.left, pair.right, &with_near).ok());
  EXPECT_EQ(cv::countNonZero(full != with_near), 0);
}

// A textured wall 8 m ahead, slanted 30 degrees (its disparities vary smoothly, so SGBM's sub-pixel bias
// averages out), seen by a right camera 0.5 m to the right and 0.15 m ahead, turned 5 degrees outwards: the
// baseline is not along the left camera's x axis, so rectification turns both views, and the depth must
// come back along the left camera's own axis, on its own pixels (along the rectified axis it is 6 % off).
TEST(StereoDepth, ATurnedPairGivesDepthAlongTheLeftCamerasAxis) {
  const CameraIntrinsics camera{400.0, 400.0, 188.0, 120.0, 376, 240};
  StereoCalibration calibration;
  calibration.left = calibration.right = camera;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(-5.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  calibration.right_from_left_rotation = turn;
  const Eigen::Vector3d right_centre(0.5, 0.0, 0.15);
  calibration.right_from_left_translation = -turn * right_centre;
  const Eigen::Matrix3d slant = Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d normal = slant.col(2), along = slant.col(0), origin(0.0, 0.0, 8.0);
  cv::Mat texture(1200, 2000, CV_8UC1);  // 1 cm per texel
  cv::randu(texture, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.5);
  // Where a ray from `centre` (left frame) meets the wall.
  const auto meet = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& ray) {
    return Eigen::Vector3d(centre + ray * (normal.dot(origin - centre) / normal.dot(ray)));
  };
  const auto view = [&](const Eigen::Matrix3d& left_from_camera, const Eigen::Vector3d& centre) {
    cv::Mat map_x(camera.height, camera.width, CV_32F), map_y(camera.height, camera.width, CV_32F);
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector3d point = meet(
            centre, left_from_camera * Eigen::Vector3d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1));
        map_x.at<float>(v, u) = static_cast<float>(along.dot(point - origin) * 100.0 + 1000.0);
        map_y.at<float>(v, u) = static_cast<float>(point.y() * 100.0 + 600.0);
      }
    }
    cv::Mat image;
    cv::remap(texture, image, map_x, map_y, cv::INTER_LINEAR);
    return image;
  };
  const cv::Mat left = view(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const cv::Mat right = view(turn.transpose(), right_centre);
  std::unique_ptr<StereoDepth> stereo;
  ASSERT_TRUE(StereoDepth::Create(calibration, StereoOptions(), &stereo).ok());
  cv::Mat depth;
  ASSERT_TRUE(stereo->Compute(left, right, &depth).ok());
  std::vector<double> ratios;  // measured / true depth
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth.at<float>(y, x);
      const Eigen::Vector3d ray((x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, 1.0);
      if (z > 0) ratios.push_back(z / meet(Eigen::Vector3d::Zero(), ray).z());
    }
  }
  ASSERT_GT(ratios.size(), 0.3 * depth.total());
  std::sort(ratios.begin(), ratios.end());
  EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.002);
}

TEST(StereoDepth, DepthOutsideTheRangeIsUnknown) {
  const WallPair pair = Wall();
  StereoOptions options;
  options.max_range_m = 7.0;
  std::unique_ptr<StereoDepth> stereo;
  ASSERT_TRUE(StereoDepth::Create(pair.calibration, options, &stereo).ok());
  cv::Mat depth;
  ASSERT_TRUE(stereo->Compute(pair.left, pair.right, &depth).ok());
  EXPECT_EQ(cv::countNonZero(depth), 0);
}

TEST(StereoDepth, RefusesPairsItCannotMatch) {
  WallPair pair = Wall();
  std::unique_ptr<StereoDepth> stereo;
  StereoCalibration above = pair.calibration;
  above.right_from_left_translation = Eigen::Vector3d(0.0, -0.5, 0.0);
  Status status = StereoDepth::Create(above, StereoOptions(), &stereo);
  EXPECT_NE(status.message().find("one above the other"), std::string::npos) << status.message();
  StereoCalibration together = pair.calibration;
  together.right_from_left_translation.setZero();
  status = StereoDepth::Create(together, StereoOptions(), &stereo);
  EXPECT_NE(status.message().find("no baseline"), std::string::npos) << status.message();
  StereoOptions options;
  options.num_disparities = 50;
  status = StereoDepth::Create(pair.calibration, options, &stereo);
  EXPECT_NE(status.message().find("depth.stereo.num_disparities = 50"), std::string::npos) << status.message();
  ASSERT_TRUE(StereoDepth::Create(pair.calibration, StereoOptions(), &stereo).ok());
  cv::Mat depth;
  status = stereo->Compute(pair.left, pair.right.colRange(0, 300), &depth);
  EXPECT_NE(status.message().find("376x240 and 300x240"), std::string::npos) << status.message();
}

// Depth fusion: a camera looking along +z flies along x past a wall 20 m ahead, 0.5 m a frame. Each frame's
// depth has independent noise of 0.8 m (the range error of 0.002 per m^2 at 20 m), more than the grid's 0.5 m.
constexpr double kFusionSigmaPerM2 = 0.002;

cv::Mat NoisyWall(const CameraIntrinsics& camera, double z, double sigma, cv::RNG* rng) {
  cv::Mat depth(camera.height, camera.width, CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) depth.at<float>(y, x) = static_cast<float>(z + rng->gaussian(sigma));
  }
  return depth;
}

// The number of views averaged at (y, x), from the fused error's scale 1 / sqrt(views) (no shared error).
int ViewsAt(const cv::Mat& scale, int y, int x) {
  const float s = scale.at<float>(y, x);
  return s > 0.0f ? static_cast<int>(std::lround(1.0 / (s * s))) : 0;
}

CameraPoseSample At(double x) {
  CameraPoseSample pose;
  pose.position = Eigen::Vector3d(x, 0.0, 0.0);
  return pose;
}

// A camera flying sideways (+x, 1 m/s) past a textured wall 8 m away, face on (f = 400 px: 50 px per metre on the
// wall): frame i stands at x = 0.2 i m, 0.2 i s into the flight, and sees the texture 10 i px further on.
struct WallFlight {
  const CameraIntrinsics camera{400.0, 400.0, 188.0, 120.0, 376, 240};
  cv::Mat texture;
  WallFlight() : texture(240, 376 + 200, CV_8UC1) {
    cv::randu(texture, 0, 256);
    cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  }
  cv::Mat Frame(int i) const { return texture.colRange(10 * i, 10 * i + 376).clone(); }
  static CameraPoseSample Pose(int i, const Eigen::Vector3d& direction = Eigen::Vector3d::UnitX()) {
    CameraPoseSample pose;
    pose.timestamp_ns = SecondsToNs(0.2 * i);
    pose.position = 0.2 * i * direction;
    return pose;
  }
};

// Each frame is matched with the earlier one whose baseline comes nearest depth.flight.baseline_m (2 m: frame i - 10),
// none before one stands min_baseline_m (0.3 m) away, and the wall comes out at its 8 m.
TEST(FlightDepth, AWallFlownPastComesOutAtItsDepth) {
  const WallFlight flight;
  FlightDepth depth(Lens(flight.camera), FlightDepthOptions(), StereoOptions());
  for (int i = 0; i <= 14; ++i) {
    cv::Mat depth_m;
    double sigma = 0.0;
    const bool paired = depth.Compute(flight.Frame(i), WallFlight::Pose(i), &depth_m, &sigma);
    EXPECT_EQ(paired, i >= 2) << "frame " << i;
    if (!paired) {
      EXPECT_TRUE(depth_m.empty());
      continue;
    }
    const double baseline = 0.2 * std::min(i, 10);
    EXPECT_NEAR(sigma, depth.SigmaPerM2(baseline), 0.02 * sigma) << "frame " << i;
    const auto [known, at_wall] = KnownAndAt(depth_m, 8.0, 0.08);
    EXPECT_GT(known, 0.6 * 376 * 240) << "frame " << i;
    EXPECT_GT(at_wall, 0.98 * known) << "frame " << i;
  }
  EXPECT_NEAR(depth.SigmaPerM2(1.0), 0.5 / 400.0, 1e-12);
  EXPECT_EQ(depth.DisparitiesFor(1.0), 128);  // 400 px * 1 m / 3.5 m = 114 px, in steps of 16
  EXPECT_NEAR(depth.NearestDepth(1.0), 400.0 / 128, 1e-12);
  EXPECT_EQ(depth.DisparitiesFor(2.0), 240);  // 400 px * 2 m / 3.5 m = 229 px
}

// Frames older than depth.flight.history_s are not kept: with 0.5 s the partner of frame 8 is frame 6, 0.4 m away.
TEST(FlightDepth, OnlyTheFramesOfTheLastSecondsAreKept) {
  const WallFlight flight;
  FlightDepthOptions options;
  options.history_s = 0.5;
  FlightDepth depth(Lens(flight.camera), options, StereoOptions());
  cv::Mat depth_m;
  double sigma = 0.0;
  for (int i = 0; i <= 8; ++i) depth.Compute(flight.Frame(i), WallFlight::Pose(i), &depth_m, &sigma);
  ASSERT_FALSE(depth_m.empty());
  EXPECT_NEAR(sigma, depth.SigmaPerM2(0.4), 0.02 * sigma);
}

// A camera flying along its optical axis has no baseline across it: no depth, whatever the distance flown.
TEST(FlightDepth, FlyingAlongTheOpticalAxisGivesNoDepth) {
  const WallFlight flight;
  FlightDepth depth(Lens(flight.camera), FlightDepthOptions(), StereoOptions());
  for (int i = 0; i <= 8; ++i) {
    cv::Mat depth_m;
    double sigma = 0.0;
    EXPECT_FALSE(depth.Compute(flight.Frame(0), WallFlight::Pose(i, Eigen::Vector3d::UnitZ()), &depth_m, &sigma));
    EXPECT_TRUE(depth_m.empty());
  }
}

TEST(DepthFusion, AgreeingFramesAverageAwayTheirNoise) {
  const CameraIntrinsics camera{100.0, 100.0, 100.0, 50.0, 200, 100};
  DepthFusion fusion(camera, FusionOptions{4, 2.0, kFusionSigmaPerM2});
  cv::RNG rng(7);
  const double sigma = kFusionSigmaPerM2 * 20.0 * 20.0;
  cv::Mat depth, scale;
  for (int frame = 0; frame < 5; ++frame) {
    depth = NoisyWall(camera, 20.0, sigma, &rng);
    fusion.Fuse(At(0.5 * frame), 4, &depth, &scale);
  }
  // The fifth frame, fused with four before it (the wall moved 2.5 px a frame: columns from 12 on are in all).
  double squares = 0.0, averaged = 0.0;
  int pixels = 0;
  for (int y = 2; y < depth.rows; y += 4) {
    for (int x = 14; x < depth.cols; x += 4) {
      squares += std::pow(depth.at<float>(y, x) - 20.0, 2);
      averaged += ViewsAt(scale, y, x);
      ++pixels;
    }
  }
  // Two frames agree within 2 combined errors 95 % of the time: about 4.8 views. A plain mean of that many would
  // be off by 0.8 / sqrt(4.8) = 0.37 m; the gate, centred on this frame's own return, keeps a little of its error
  // (0.43 m with this seed). One frame alone: 0.8 m.
  EXPECT_GT(averaged / pixels, 4.6);
  EXPECT_LT(std::sqrt(squares / pixels), 0.6 * sigma);
  EXPECT_GT(std::sqrt(squares / pixels), 0.4 * sigma);
  EXPECT_EQ(scale.at<float>(3, 14), 0.0f);  // off the lattice: left as it was
}

TEST(DepthFusion, AFrameThatSawAnotherSurfaceIsNotAveraged) {
  const CameraIntrinsics camera{100.0, 100.0, 100.0, 50.0, 200, 100};
  DepthFusion fusion(camera, FusionOptions{2, 2.0, kFusionSigmaPerM2});
  cv::Mat scale;
  cv::Mat before(camera.height, camera.width, CV_32F, cv::Scalar(10.0));  // something 10 m ahead, then gone
  fusion.Fuse(At(0.0), 4, &before, &scale);
  EXPECT_EQ(ViewsAt(scale, 2, 2), 1);
  cv::Mat wall(camera.height, camera.width, CV_32F, cv::Scalar(20.0));
  wall.at<float>(6, 6) = 0.0f;  // no return
  fusion.Fuse(At(0.0), 4, &wall, &scale);
  EXPECT_EQ(ViewsAt(scale, 10, 10), 1);
  EXPECT_EQ(wall.at<float>(10, 10), 20.0f);
  EXPECT_EQ(ViewsAt(scale, 6, 6), 0);
  cv::Mat again(camera.height, camera.width, CV_32F, cv::Scalar(20.4));  // the wall again, within the gate
  fusion.Fuse(At(0.0), 4, &again, &scale);
  EXPECT_EQ(ViewsAt(scale, 10, 10), 2);  // the wall seen before, not what stood in front of it
  EXPECT_NEAR(again.at<float>(10, 10), 20.2, 1e-5);
  EXPECT_EQ(ViewsAt(scale, 6, 6), 1);  // the frame before had no return there
}

// A frame's noise counts once: the frames kept are the ones that came, not their fused depths.
TEST(DepthFusion, FramesAreKeptAsTheyCameNotAsFused) {
  const CameraIntrinsics camera{100.0, 100.0, 100.0, 50.0, 200, 100};
  DepthFusion fusion(camera, FusionOptions{2, 2.0, kFusionSigmaPerM2});
  cv::Mat scale;
  for (const float z : {20.0f, 21.0f}) {
    cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(z));
    fusion.Fuse(At(0.0), 4, &depth, &scale);
  }
  cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(20.0));
  fusion.Fuse(At(0.0), 4, &depth, &scale);
  EXPECT_EQ(ViewsAt(scale, 10, 10), 3);
  EXPECT_NEAR(depth.at<float>(10, 10), (20.0 + 21.0 + 20.0) / 3.0, 1e-5);  // 20.17 with the second frame fused
}

// Frames that see a surface from the same distance share part of their error: averaging them shrinks only the rest.
TEST(DepthFusion, AnErrorTheFramesShareIsNotAveragedAway) {
  const CameraIntrinsics camera{100.0, 100.0, 100.0, 50.0, 200, 100};
  const auto scale_after_five = [&](double shared) {
    DepthFusion fusion(camera, FusionOptions{4, 2.0, kFusionSigmaPerM2, shared});
    cv::Mat scale;
    for (int frame = 0; frame < 5; ++frame) {
      cv::Mat wall(camera.height, camera.width, CV_32F, cv::Scalar(20.0));
      fusion.Fuse(At(0.0), 4, &wall, &scale);
    }
    return scale.at<float>(10, 10);
  };
  EXPECT_NEAR(scale_after_five(0.0), std::sqrt(1.0 / 5.0), 1e-6);
  EXPECT_NEAR(scale_after_five(0.25), std::sqrt(0.25 + 0.75 / 5.0), 1e-6);  // 0.63 instead of 0.45
  EXPECT_NEAR(scale_after_five(1.0), 1.0, 1e-6);                            // all shared: no gain
  EXPECT_NEAR(DepthFusion(camera, FusionOptions{4, 2.0, kFusionSigmaPerM2, 0.5}).ErrorScale(1), 1.0, 1e-12);
}

TEST(DepthFusion, WithoutFramesKeptDepthIsUntouched) {
  const CameraIntrinsics camera{100.0, 100.0, 100.0, 50.0, 200, 100};
  DepthFusion fusion(camera, FusionOptions{0, 2.0, kFusionSigmaPerM2});
  cv::Mat scale, depth(camera.height, camera.width, CV_32F, cv::Scalar(20.0));
  for (int frame = 0; frame < 3; ++frame) fusion.Fuse(At(0.5 * frame), 4, &depth, &scale);
  EXPECT_EQ(ViewsAt(scale, 2, 2), 1);
  EXPECT_EQ(cv::countNonZero(depth != 20.0f), 0);
}

// EuRoC's cam0 (MH_01's sensor.yaml): 752x480, k1 -0.28.
const CameraIntrinsics kEurocCamera{458.654, 457.296, 367.215, 248.375, 752, 480};
const Distortion kEurocDistortion{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};

TEST(Lens, ARawPixelsRayProjectsBackOntoIt) {
  const Lens lens(kEurocCamera, kEurocDistortion);
  ASSERT_TRUE(lens.distorted());
  double worst = 0.0;
  for (int v = 0; v < kEurocCamera.height; v += 7) {
    for (int u = 0; u < kEurocCamera.width; u += 7) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(lens.Project(4.0 * lens.Ray(u, v), &pixel)) << u << " " << v;
      worst = std::max(worst, (pixel - Eigen::Vector2d(u, v)).norm());
    }
  }
  EXPECT_LT(worst, 0.01);
  // The corner's ray leans out farther than a pinhole's would: the lens compresses the edge.
  const Eigen::Vector3d corner = lens.Ray(0, 0);
  EXPECT_LT(corner.x(), -1.2 * kEurocCamera.cx / kEurocCamera.fx);
  // Behind the camera, or beyond the widest ray (where k1 < 0 would fold the point back into the image): nowhere.
  Eigen::Vector2d pixel;
  EXPECT_FALSE(lens.Project({0.0, 0.0, -1.0}, &pixel));
  EXPECT_FALSE(lens.Project({3.0, 0.0, 1.0}, &pixel));
}

TEST(Lens, WithoutDistortionItIsAPinholeAndTheImageIsLeftAlone) {
  const Lens lens(kEurocCamera);
  EXPECT_FALSE(lens.distorted());
  EXPECT_TRUE(lens.pinhole_at().empty());
  const Eigen::Vector3d ray = lens.Ray(100, 50);
  EXPECT_NEAR(ray.x(), (100 - kEurocCamera.cx) / kEurocCamera.fx, 1e-12);
  EXPECT_NEAR(ray.y(), (50 - kEurocCamera.cy) / kEurocCamera.fy, 1e-12);
  const cv::Mat image(480, 752, CV_32F, cv::Scalar(3.0f));
  EXPECT_EQ(lens.ToRaw(image).data, image.data);
}

// The largest coefficients a map may hold: the undistortion may not converge, but nothing is left undefined.
TEST(Lens, AnExtremeLensLeavesNoPixelUndefined) {
  const CameraIntrinsics camera{100.0, 100.0, 31.5, 23.5, 64, 48};
  const Lens lens(camera, {0.0, 0.0, 9.9, 9.9});  // OpenCV gives most pixels no finite undistorted place
  ASSERT_TRUE(lens.distorted());
  const cv::Mat raw = lens.ToRaw(cv::Mat(48, 64, CV_32F, cv::Scalar(5.0f)));
  EXPECT_EQ(cv::countNonZero(raw != raw), 0);  // no NaN
  for (int v = 0; v < camera.height; v += 5) {
    for (int u = 0; u < camera.width; u += 5) {
      ASSERT_TRUE(lens.Ray(u, v).allFinite());
      Eigen::Vector2d pixel;
      if (lens.Project(lens.Ray(u, v), &pixel)) ASSERT_TRUE(pixel.allFinite());
    }
  }
}

TEST(Lens, ToRawTakesEachRawPixelFromItsUndistortedPlace) {
  const Lens lens(kEurocCamera, kEurocDistortion);
  cv::Mat pinhole(480, 752, CV_32F);  // each pixel holds its column
  for (int v = 0; v < pinhole.rows; ++v)
    for (int u = 0; u < pinhole.cols; ++u) pinhole.at<float>(v, u) = static_cast<float>(u);
  const cv::Mat raw = lens.ToRaw(pinhole);
  // At the left edge's middle the raw pixel's undistorted place lies left of the image: nothing there.
  EXPECT_EQ(raw.at<float>(248, 0), 0.0f);
  const cv::Vec2f inner = lens.pinhole_at().at<cv::Vec2f>(248, 60);
  EXPECT_LT(inner[0], 60.0f);  // pulled outwards
  EXPECT_EQ(raw.at<float>(248, 60), std::round(inner[0]));
  EXPECT_NEAR(raw.at<float>(248, 367), 367.0f, 1.0f);  // the centre stays
}

// Mirroring, transposing or turning an image changes its lens's tangential terms: a point projects through the
// changed lens where the changed image shows it.
TEST(Lens, AMirroredTransposedOrTurnedImageHasItsOwnTangentialTerms) {
  const Distortion d{-0.2, 0.05, 0.01, -0.02};
  const CameraIntrinsics c{400.0, 400.0, 0.0, 0.0, 600, 400};  // centre at the origin: the turns need no shift
  const Lens lens(c, d);
  const Lens mirrored(c, MirroredDistortion(d)), transposed(c, TransposedDistortion(d)), turned(c, TurnedDistortion(d));
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector3d(-0.25, 0.35, 1.0)}) {
    Eigen::Vector2d seen, other;
    ASSERT_TRUE(lens.Project(point, &seen));
    ASSERT_TRUE(mirrored.Project({-point.x(), point.y(), point.z()}, &other));
    EXPECT_NEAR(other.x(), -seen.x(), 1e-9);
    EXPECT_NEAR(other.y(), seen.y(), 1e-9);
    ASSERT_TRUE(transposed.Project({point.y(), point.x(), point.z()}, &other));
    EXPECT_NEAR(other.x(), seen.y(), 1e-9);
    EXPECT_NEAR(other.y(), seen.x(), 1e-9);
    ASSERT_TRUE(turned.Project({-point.y(), point.x(), point.z()}, &other));  // x' = -y, y' = x
    EXPECT_NEAR(other.x(), -seen.y(), 1e-9);
    EXPECT_NEAR(other.y(), seen.x(), 1e-9);
  }
}

}  // namespace
}  // namespace patrolmap::depth
