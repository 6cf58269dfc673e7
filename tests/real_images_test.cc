// The flow stage on real images, with ground truth. Each test skips when its data is absent:
// ../shared/data (KITTI excerpt) and Debian's opencv-doc (building.jpg).
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/LU>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/flow/edge_flow.h"

namespace patrolmap::flow {
namespace {

const std::string kKitti = std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data/kitti_seq2";
const std::string kOpencvData = "/usr/share/doc/opencv-doc/examples/data";

// KITTI poses.txt: one 3x4 camera-to-world matrix per line.
std::vector<Eigen::Matrix4d> ReadPoses(const std::string& path) {
  std::vector<Eigen::Matrix4d> poses;
  std::ifstream stream(path);
  for (std::string line; std::getline(stream, line);) {
    std::istringstream values(line);
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 12; ++i) values >> pose(i / 4, i % 4);
    poses.push_back(pose);
  }
  return poses;
}

// Intrinsics from the first projection matrix of calib.txt (with or without a "P0:" label).
Eigen::Matrix3d ReadIntrinsics(const std::string& path) {
  std::ifstream stream(path);
  std::string line;
  std::getline(stream, line);
  if (line.find(':') != std::string::npos) line = line.substr(line.find(':') + 1);
  std::istringstream values(line);
  double p[12];
  for (double& value : p) values >> value;
  Eigen::Matrix3d k;
  k << p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10];
  return k;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// Sampson distance of a correspondence to the epipolar geometry F [pixels].
double Sampson(const Eigen::Matrix3d& f, const cv::Point2f& a, const cv::Point2f& b) {
  const Eigen::Vector3d x1(a.x, a.y, 1.0), x2(b.x, b.y, 1.0);
  const Eigen::Vector3d fx1 = f * x1, ftx2 = f.transpose() * x2;
  const double residual = x2.dot(fx1);
  return std::abs(residual) /
         std::sqrt(fx1.x() * fx1.x() + fx1.y() * fx1.y() + ftx2.x() * ftx2.x() + ftx2.y() * ftx2.y());
}

// Sampson distances [pixels] of the edge flow tracked over the 51 KITTI frames, measured against
// the epipolar geometry of the ground-truth poses (x2^T F x1 = 0).
std::vector<double> KittiEpipolarErrors(const TrackerOptions& options) {
  const std::vector<Eigen::Matrix4d> poses = ReadPoses(kKitti + "/poses.txt");
  const Eigen::Matrix3d k = ReadIntrinsics(kKitti + "/calib.txt");
  EdgeFlowTracker tracker(EdgeOptions{}, options);
  std::vector<FlowVector> vectors;
  std::vector<double> errors;
  for (int frame = 0; frame < static_cast<int>(poses.size()); ++frame) {
    const cv::Mat image = cv::imread(kKitti + cv::format("/image_l/%06d.png", frame), cv::IMREAD_GRAYSCALE);
    if (image.empty()) return {};
    tracker.Track(image, &vectors);
    if (frame == 0) continue;
    const Eigen::Matrix4d later_from_earlier = poses[frame].inverse() * poses[frame - 1];
    const Eigen::Matrix3d f = k.inverse().transpose() * Skew(later_from_earlier.block<3, 1>(0, 3)) *
                              later_from_earlier.block<3, 3>(0, 0) * k.inverse();
    for (const FlowVector& v : vectors) errors.push_back(Sampson(f, v.start, v.start + v.delta));
  }
  std::sort(errors.begin(), errors.end());
  return errors;
}

double Quantile(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * sorted.size())];
}

// A car driving a rural road: most tracks are exact; occluding contours and foliage give a tail of wrong
// ones, which the forward-backward check removes.
TEST(RealImages, KittiEdgeFlowFollowsTheGroundTruthEpipolarGeometry) {
  if (!std::filesystem::exists(kKitti + "/poses.txt")) GTEST_SKIP() << "shared KITTI excerpt not present";
  TrackerOptions options;
  const std::vector<double> all = KittiEpipolarErrors(options);
  ASSERT_GT(all.size(), 5000u);
  EXPECT_LT(Quantile(all, 0.50), 0.5);
  EXPECT_LT(Quantile(all, 0.75), 1.5);
  options.max_forward_backward_px = 1.0;
  const std::vector<double> checked = KittiEpipolarErrors(options);
  EXPECT_GT(checked.size(), all.size() * 6 / 10);
  EXPECT_LT(Quantile(checked, 0.90), 1.5);
  EXPECT_LT(Quantile(checked, 0.90), Quantile(all, 0.90) / 3.0);
}

// A real facade photo moved by a known amount: the tracker recovers it.
TEST(RealImages, BuildingPhotoShiftIsRecovered) {
  const cv::Mat photo = cv::imread(kOpencvData + "/building.jpg", cv::IMREAD_GRAYSCALE);
  if (photo.empty()) GTEST_SKIP() << "opencv-doc not installed";
  cv::Mat image;
  cv::resize(photo, image, cv::Size(376, 240), 0, 0, cv::INTER_AREA);
  EdgeFlowTracker tracker(EdgeOptions{}, TrackerOptions{});
  std::vector<FlowVector> vectors;
  cv::Mat moved;
  for (int step = 0; step <= 4; ++step) {  // 0, 3, 6, 9, 12 px to the left and 1 px down per step
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -3.0 * step, 0, 1, 1.0 * step);
    cv::warpAffine(image, moved, shift, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    tracker.Track(moved, &vectors);
  }
  ASSERT_GT(vectors.size(), 200u);
  int close = 0;
  for (const FlowVector& v : vectors) close += std::abs(v.delta.x + 3.0f) < 0.3f && std::abs(v.delta.y - 1.0f) < 0.3f;
  EXPECT_GT(close, static_cast<int>(0.9 * vectors.size()));
}

}  // namespace
}  // namespace patrolmap::flow
