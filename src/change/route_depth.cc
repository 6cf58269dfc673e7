#include "patrolmap/change/route_depth.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/depth/motion_stereo.h"

namespace patrolmap::change {
namespace {

depth::MotionStereoOptions MatchingOptions(const RouteDepthOptions& options) {
  depth::MotionStereoOptions motion;
  motion.min_baseline_m = options.baselines.min_baseline_m;
  motion.min_sideways_share = options.baselines.min_sideways_share;
  motion.matching = options.matching;
  motion.matching.num_disparities = options.num_disparities;
  motion.agree_m = options.min_change_m;
  motion.agree_sigmas = options.sigmas;
  return motion;
}

using depth::RelativePose;

// The depth image with each pixel the least depth around it (one pixel each way), and unknown (0) wherever a pixel
// around it is unknown: a ray that lands beside a depth edge is compared with the nearer surface.
cv::Mat NearestAround(const cv::Mat& depth) {
  cv::Mat nearest;
  cv::erode(depth, nearest, cv::Mat());
  return nearest;
}

// Where `from`'s surfaces lie in space `into` saw through: for each pixel of `from` with depth, its point in
// `into`'s camera is compared with `into`'s depth there. A hit marks, in `marks` (of the current frame), the
// pixel of `from` itself (`at_source`) or the pixel of `into` it lands on.
void MarkSeenThrough(const KeyFrameView& from, const KeyFrameView& into, const cv::Mat& into_nearest,
                     const RouteDepthOptions& options, bool at_source, cv::Mat* marks) {
  const RelativePose into_from(from.pose, into.pose);
  for (int v = 0; v < from.depth.rows; ++v) {
    const float* z = from.depth.ptr<float>(v);
    for (int u = 0; u < from.depth.cols; ++u) {
      if (!(z[u] > 0.0f)) continue;
      const Eigen::Vector3d in_into = into_from.rotation * (z[u] * from.lens.Ray(u, v)) + into_from.translation;
      Eigen::Vector2d pixel;
      if (!into.lens.Project(in_into, &pixel)) continue;
      const int ub = static_cast<int>(std::lround(pixel.x())), vb = static_cast<int>(std::lround(pixel.y()));
      if (ub < 0 || vb < 0 || ub >= into_nearest.cols || vb >= into_nearest.rows) continue;
      const double seen = into_nearest.at<float>(vb, ub);
      if (!(seen > 0.0)) continue;
      const double error = from.range_sigma_per_m2 * z[u] * z[u] + into.range_sigma_per_m2 * seen * seen;
      const double margin = std::max(options.min_change_m, options.sigmas * error);
      if (seen <= in_into.z() + margin) continue;
      if (at_source) {
        marks->at<std::uint8_t>(v, u) = 255;
      } else {
        marks->at<std::uint8_t>(vb, ub) = 255;
      }
    }
  }
}

}  // namespace

bool AddMotionDepth(const std::vector<RouteNeighbour>& neighbours, const depth::Lens& lens,
                    const CameraPoseSample& pose, const RouteDepthOptions& options, KeyFrameView* view) {
  const CameraIntrinsics& camera = lens.camera();
  if (view->image.empty() || !camera.valid() || camera.width != view->image.cols || camera.height != view->image.rows) {
    return false;
  }
  double fused_sigma = 0.0;
  const cv::Mat fused = depth::MotionDepth(view->image, pose, neighbours, lens, MatchingOptions(options), &fused_sigma);
  if (fused.empty()) return false;
  view->depth = lens.ToRaw(fused);
  view->lens = lens;
  view->pose = pose;
  view->range_sigma_per_m2 = fused_sigma;
  return true;
}

cv::Mat VisibilityChange(const KeyFrameView& prior, const KeyFrameView& current, const RouteDepthOptions& options) {
  if (prior.depth.empty() || current.depth.empty()) return cv::Mat();
  cv::Mat marks = cv::Mat::zeros(current.depth.size(), CV_8U);
  MarkSeenThrough(current, prior, NearestAround(prior.depth), options, true, &marks);     // new surfaces
  MarkSeenThrough(prior, current, NearestAround(current.depth), options, false, &marks);  // surfaces gone
  return marks;
}

std::optional<ParallaxPrediction> PredictParallax(const KeyFrameView& prior, const KeyFrameView& current,
                                                  const cv::Mat& current_from_prior, const cv::Mat& marks,
                                                  const cv::Rect& box, const RouteDepthOptions& options) {
  if (prior.depth.empty() || current.depth.empty() || current_from_prior.empty() || marks.empty()) return std::nullopt;
  const cv::Rect inside = box & cv::Rect(0, 0, current.depth.cols, current.depth.rows);
  if (inside.area() == 0) return std::nullopt;
  if (cv::countNonZero(marks(inside)) < options.parallax_min_marked_share * inside.area()) return std::nullopt;
  const RelativePose prior_from(current.pose, prior.pose);
  Eigen::Matrix3d homography;
  cv::cv2eigen(current_from_prior, homography);
  std::vector<double> dx, dy;
  int known = 0;
  for (int v = inside.y; v < inside.br().y; ++v) {
    const float* z = current.depth.ptr<float>(v);
    for (int u = inside.x; u < inside.br().x; ++u) {
      if (!(z[u] > 0.0f)) continue;
      ++known;
      Eigen::Vector2d pixel;
      const Eigen::Vector3d in_prior = prior_from.rotation * (z[u] * current.lens.Ray(u, v)) + prior_from.translation;
      if (!prior.lens.Project(in_prior, &pixel)) continue;
      const Eigen::Vector3d carried = homography * pixel.homogeneous();
      if (!(carried.z() > 0.0)) continue;
      dx.push_back(carried.x() / carried.z() - u);
      dy.push_back(carried.y() / carried.z() - v);
    }
  }
  if (known == 0 || known < options.parallax_known_share * inside.area() ||
      2 * dx.size() < static_cast<std::size_t>(known)) {
    return std::nullopt;
  }
  const auto median = [](std::vector<double>* values) {
    std::nth_element(values->begin(), values->begin() + values->size() / 2, values->end());
    return (*values)[values->size() / 2];
  };
  return ParallaxPrediction{cv::Point2d(median(&dx), median(&dy)), options.parallax_slack_px};
}

}  // namespace patrolmap::change
