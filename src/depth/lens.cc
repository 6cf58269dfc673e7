#include "patrolmap/depth/lens.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace patrolmap::depth {
namespace {

// Iterations of the undistortion's fixed point: OpenCV's default of 5 leaves EuRoC cam0's corners (k1 -0.28) 0.29 px
// off; 20 bring every pixel within 0.01 px (test Lens.ARawPixelsRayProjectsBackOntoIt).
constexpr int kUndistortIterations = 20;
constexpr double kUndistortEpsilon = 1e-9;

}  // namespace

Lens::Lens(const CameraIntrinsics& camera, const Distortion& distortion) : camera_(camera), distortion_(distortion) {
  const bool none = std::all_of(distortion.begin(), distortion.end(), [](double k) { return k == 0.0; });
  if (none || !camera.valid()) return;
  std::vector<cv::Point2f> raw;
  raw.reserve(static_cast<std::size_t>(camera.width) * camera.height);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) raw.emplace_back(static_cast<float>(u), static_cast<float>(v));
  const cv::Matx33d k(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
  std::vector<cv::Point2f> pinhole;
  cv::undistortPoints(
      raw, pinhole, k, cv::Mat(distortion), cv::noArray(), k,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, kUndistortIterations, kUndistortEpsilon));
  for (cv::Point2f& p : pinhole) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {  // the fixed point diverged: a pixel no ray reaches
      p = cv::Point2f(-1.0f, -1.0f);
      continue;
    }
    const double x = (p.x - camera.cx) / camera.fx, y = (p.y - camera.cy) / camera.fy;
    widest_squared_ = std::max(widest_squared_, x * x + y * y);
  }
  pinhole_at_ = cv::Mat(pinhole, true).reshape(2, camera.height);
}

Eigen::Vector3d Lens::Ray(int u, int v) const {
  if (!distorted()) return {(u - camera_.cx) / camera_.fx, (v - camera_.cy) / camera_.fy, 1.0};
  const cv::Vec2f p = pinhole_at_.at<cv::Vec2f>(v, u);
  return {(p[0] - camera_.cx) / camera_.fx, (p[1] - camera_.cy) / camera_.fy, 1.0};
}

bool Lens::Project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const {
  if (!(point.z() > 0.0)) return false;
  Eigen::Vector2d seen = point.head<2>() / point.z();
  if (distorted()) {
    if (seen.squaredNorm() > widest_squared_) return false;
    seen = Distorted(distortion_, seen);
  }
  *pixel = {camera_.fx * seen.x() + camera_.cx, camera_.fy * seen.y() + camera_.cy};
  return true;
}

cv::Mat Lens::ToRaw(const cv::Mat& pinhole) const {
  if (!distorted() || pinhole.empty()) return pinhole;
  cv::Mat raw;
  cv::remap(pinhole, raw, pinhole_at_, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar());
  return raw;
}

Distortion MirroredDistortion(const Distortion& d) { return {d[0], d[1], d[2], -d[3]}; }
Distortion TransposedDistortion(const Distortion& d) { return {d[0], d[1], d[3], d[2]}; }
Distortion TurnedDistortion(const Distortion& d) { return {d[0], d[1], d[3], -d[2]}; }

}  // namespace patrolmap::depth
