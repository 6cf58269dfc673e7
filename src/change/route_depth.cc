#include "patrolmap/change/route_depth.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/depth/stereo.h"

namespace patrolmap::change {
namespace {

depth::StereoOptions MatchingOptions(const RouteDepthOptions& options) {
  depth::StereoOptions stereo;
  stereo.num_disparities = options.num_disparities;
  stereo.block_size = options.block_size;
  stereo.disparity_sigma_px = options.disparity_sigma_px;
  stereo.max_range_m = options.max_range_m;
  return stereo;
}

// The rigid motion taking points from the axes of a camera at `from` into those of a camera at `into`:
// into.ToCamera(from.ToWorld(p)) as one matrix and one offset, for loops over every pixel.
struct RelativePose {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  RelativePose(const CameraPoseSample& from, const CameraPoseSample& into)
      : rotation((into.rotation.conjugate() * from.rotation).toRotationMatrix()),
        translation(into.ToCamera(from.position)) {}
};

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

// The image mirrored, transposed or turned so that a baseline in camera axes points along +x: a stereo pair must stand
// side by side, the other camera to the right. The matching keeps the image's rows where it can (a mirror rather than
// a half turn for a neighbour to the left): semi-global matching's paths run one way down the image.
struct SideBySide {
  enum Kind { kAsIs, kMirrored, kTransposed, kTurned } kind = kAsIs;  // kTurned: a clockwise quarter turn

  static SideBySide Towards(const Eigen::Vector3d& baseline) {
    const double along[4] = {baseline.x(), -baseline.x(), baseline.y(), -baseline.y()};
    return {static_cast<Kind>(std::max_element(along, along + 4) - along)};
  }
  // Camera axes after (x' = axes * x).
  Eigen::Matrix3d Axes() const {
    Eigen::Matrix3d axes;
    switch (kind) {
      case kAsIs: axes << 1, 0, 0, 0, 1, 0, 0, 0, 1; break;
      case kMirrored: axes << -1, 0, 0, 0, 1, 0, 0, 0, 1; break;
      case kTransposed: axes << 0, 1, 0, 1, 0, 0, 0, 0, 1; break;
      case kTurned: axes << 0, -1, 0, 1, 0, 0, 0, 0, 1; break;
    }
    return axes;
  }
  CameraIntrinsics Camera(const CameraIntrinsics& c) const {
    CameraIntrinsics t = c;
    if (kind == kMirrored) t.cx = c.width - 1 - c.cx;
    if (kind == kTransposed || kind == kTurned) {
      t.fx = c.fy, t.fy = c.fx, t.cx = c.cy, t.cy = c.cx, t.width = c.height, t.height = c.width;
      if (kind == kTurned) t.cx = c.height - 1 - c.cy;  // u' = (height - 1) - v, v' = u
    }
    return t;
  }
  Distortion LensOf(const Distortion& d) const {
    switch (kind) {
      case kAsIs: return d;
      case kMirrored: return depth::MirroredDistortion(d);
      case kTransposed: return depth::TransposedDistortion(d);
      case kTurned: return depth::TurnedDistortion(d);
    }
    return d;
  }
  // `image` as matched, into a new image (never the caller's pixels).
  cv::Mat Image(const cv::Mat& image) const {
    cv::Mat out;
    switch (kind) {
      case kAsIs: return image;
      case kMirrored: cv::flip(image, out, 1); break;
      case kTransposed: cv::transpose(image, out); break;
      case kTurned: cv::rotate(image, out, cv::ROTATE_90_CLOCKWISE); break;
    }
    return out;
  }
  // A matched image brought back.
  cv::Mat Back(const cv::Mat& image) const {
    if (kind != kTurned) return Image(image);  // mirroring and transposing undo themselves
    cv::Mat out;
    cv::rotate(image, out, cv::ROTATE_90_COUNTERCLOCKWISE);
    return out;
  }
};

// Depth of the frame seen from `pose` by matching it against `other` (seen from `other_pose`), on the lens's
// undistorted grid; the range error per squared metre into `sigma_per_m2`. Empty when the two stand too close or along
// the optical axis. Whichever way across the optical axis the other camera stands (a camera looking sideways that flies
// forward or back, or one looking down), the pair is matched side by side (SideBySide).
cv::Mat PairDepth(const cv::Mat& image, const RouteNeighbour& other, const depth::Lens& lens,
                  const CameraPoseSample& pose, const RouteDepthOptions& options, double* sigma_per_m2) {
  const Eigen::Vector3d baseline = pose.ToCamera(other.pose.position);  // the other camera, seen from this one
  const double length = baseline.norm();
  if (other.image.size() != image.size() || length < options.min_baseline_m ||
      std::hypot(baseline.x(), baseline.y()) < options.min_sideways_share * length) {
    return cv::Mat();
  }
  const SideBySide turn = SideBySide::Towards(baseline);
  const Eigen::Matrix3d axes = turn.Axes();
  StereoCalibration calibration;
  calibration.left = calibration.right = turn.Camera(lens.camera());
  calibration.left_distortion = calibration.right_distortion = turn.LensOf(lens.distortion());
  const RelativePose other_from(pose, other.pose);
  calibration.right_from_left_rotation = axes * other_from.rotation * axes.transpose();
  calibration.right_from_left_translation = axes * other_from.translation;
  std::unique_ptr<depth::StereoDepth> stereo;
  if (!depth::StereoDepth::Create(calibration, MatchingOptions(options), &stereo).ok()) return cv::Mat();
  cv::Mat depth_m;
  if (!stereo->Compute(turn.Image(image), turn.Image(other.image), &depth_m).ok()) return cv::Mat();
  *sigma_per_m2 = stereo->RangeSigma(1.0);
  return turn.Back(depth_m);
}

// `a` and `b` fused into `a`: averaged where both know the depth and agree within `sigmas` range errors (at least
// min_change_m), unknown where they disagree, and the one depth where only one knows it.
void Fuse(const cv::Mat& b, double sigma_a, double sigma_b, const RouteDepthOptions& options, cv::Mat* a) {
  for (int y = 0; y < a->rows; ++y) {
    float* za = a->ptr<float>(y);
    const float* zb = b.ptr<float>(y);
    for (int x = 0; x < a->cols; ++x) {
      if (!(zb[x] > 0.0f)) continue;
      if (!(za[x] > 0.0f)) {
        za[x] = zb[x];
        continue;
      }
      const double error = sigma_a * za[x] * za[x] + sigma_b * zb[x] * zb[x];
      const bool agree = std::abs(za[x] - zb[x]) <= std::max(options.min_change_m, options.sigmas * error);
      za[x] = agree ? 0.5f * (za[x] + zb[x]) : 0.0f;
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
  cv::Mat fused;
  double fused_sigma = 0.0;
  for (const RouteNeighbour& other : neighbours) {
    double sigma = 0.0;
    const cv::Mat depth_m = PairDepth(view->image, other, lens, pose, options, &sigma);
    if (depth_m.empty()) continue;
    if (fused.empty()) {
      fused = depth_m, fused_sigma = sigma;
    } else {
      Fuse(depth_m, fused_sigma, sigma, options, &fused);
      fused_sigma = std::max(fused_sigma, sigma);
    }
  }
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

void DropWhereDepthAgrees(const KeyFrameView& prior, const KeyFrameView& current, const cv::Mat& marks,
                          const RouteDepthOptions& options, AppearanceChange* change) {
  if (options.unchanged_max_marked_share <= 0.0 || prior.depth.empty() || current.depth.empty() || marks.empty()) {
    return;  // off (no share is under 0), or nothing to test
  }
  const auto share = [](const cv::Mat& image, const cv::Rect& box) {  // of the box's pixels above 0
    const cv::Rect inside = box & cv::Rect(0, 0, image.cols, image.rows);
    return inside.area() > 0 ? static_cast<double>(cv::countNonZero(image(inside) > 0)) / inside.area() : 0.0;
  };
  std::vector<AppearanceRegion> kept;
  for (AppearanceRegion& region : change->regions) {
    const bool same = share(current.depth, region.current_box) >= options.unchanged_known_share &&
                      share(prior.depth, region.prior_box) >= options.unchanged_known_share &&
                      share(marks, region.current_box) < options.unchanged_max_marked_share;
    if (same) {
      change->dropped.push_back({std::move(region), DropReason::kSameDepth});
    } else {
      kept.push_back(std::move(region));
    }
  }
  change->regions = std::move(kept);
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
