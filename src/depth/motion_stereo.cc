#include "patrolmap/depth/motion_stereo.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <opencv2/core.hpp>

#include "patrolmap/depth/stereo.h"

namespace patrolmap::depth {
namespace {

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
      case kMirrored: return MirroredDistortion(d);
      case kTransposed: return TransposedDistortion(d);
      case kTurned: return TurnedDistortion(d);
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

// Depth of the frame seen from `pose` by matching it against `other`, on the lens's undistorted grid; the range error
// per squared metre into `sigma_per_m2`. Empty when the two stand too close or along the optical axis. Whichever way
// across the optical axis the other camera stands (a camera looking sideways that flies forward or back, or one
// looking down), the pair is matched side by side (SideBySide).
cv::Mat PairDepth(const cv::Mat& image, const MotionFrame& other, const Lens& lens, const CameraPoseSample& pose,
                  const MotionStereoOptions& options, double* sigma_per_m2) {
  if (other.image.size() != image.size() || !UsableBaseline(pose, other.pose, options)) return cv::Mat();
  const SideBySide turn = SideBySide::Towards(pose.ToCamera(other.pose.position));
  const Eigen::Matrix3d axes = turn.Axes();
  StereoCalibration calibration;
  calibration.left = calibration.right = turn.Camera(lens.camera());
  calibration.left_distortion = calibration.right_distortion = turn.LensOf(lens.distortion());
  const RelativePose other_from(pose, other.pose);
  calibration.right_from_left_rotation = axes * other_from.rotation * axes.transpose();
  calibration.right_from_left_translation = axes * other_from.translation;
  std::unique_ptr<StereoDepth> stereo;
  if (!StereoDepth::Create(calibration, options.matching, &stereo).ok()) return cv::Mat();
  cv::Mat depth_m;
  if (!stereo->Compute(turn.Image(image), turn.Image(other.image), &depth_m).ok()) return cv::Mat();
  *sigma_per_m2 = stereo->RangeSigma(1.0);
  return turn.Back(depth_m);
}

// `a` and `b` fused into `a`: averaged where both know the depth and agree (MotionStereoOptions::agree_m and
// agree_sigmas), unknown where they disagree, and the one depth where only one knows it.
void Fuse(const cv::Mat& b, double sigma_a, double sigma_b, const MotionStereoOptions& options, cv::Mat* a) {
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
      const bool agree = std::abs(za[x] - zb[x]) <= std::max(options.agree_m, options.agree_sigmas * error);
      za[x] = agree ? 0.5f * (za[x] + zb[x]) : 0.0f;
    }
  }
}

}  // namespace

bool UsableBaseline(const CameraPoseSample& pose, const CameraPoseSample& other, const MotionStereoOptions& options) {
  const Eigen::Vector3d baseline = pose.ToCamera(other.position);  // the other camera, seen from this one
  const double length = baseline.norm();
  return length >= options.min_baseline_m &&
         std::hypot(baseline.x(), baseline.y()) >= options.min_sideways_share * length;
}

cv::Mat MotionDepth(const cv::Mat& image, const CameraPoseSample& pose, const std::vector<MotionFrame>& others,
                    const Lens& lens, const MotionStereoOptions& options, double* sigma_per_m2) {
  cv::Mat fused;
  double fused_sigma = 0.0;
  for (const MotionFrame& other : others) {
    double sigma = 0.0;
    const cv::Mat depth_m = PairDepth(image, other, lens, pose, options, &sigma);
    if (depth_m.empty()) continue;
    if (fused.empty()) {
      fused = depth_m, fused_sigma = sigma;
    } else {
      Fuse(depth_m, fused_sigma, sigma, options, &fused);
      fused_sigma = std::max(fused_sigma, sigma);
    }
  }
  *sigma_per_m2 = fused_sigma;
  return fused;
}

FlightDepth::FlightDepth(const Lens& lens, const FlightDepthOptions& flight, const StereoOptions& matching)
    : lens_(lens), flight_(flight) {
  stereo_.min_baseline_m = flight.min_baseline_m;
  stereo_.min_sideways_share = flight.min_sideways_share;
  stereo_.matching = matching;
}

double FlightDepth::SigmaPerM2(double baseline_m) const {
  return stereo_.matching.disparity_sigma_px / (lens_.camera().fx * baseline_m);
}

int FlightDepth::DisparitiesFor(double baseline_m) const {
  constexpr int kStep = 16, kMost = 512;  // SGBM's disparity ranges
  const double needed = lens_.camera().fx * baseline_m / flight_.min_range_m;
  return std::clamp(kStep * static_cast<int>(std::ceil(needed / kStep)), kStep, kMost);
}

double FlightDepth::NearestDepth(double baseline_m) const {
  return lens_.camera().fx * baseline_m / DisparitiesFor(baseline_m);
}

const MotionFrame* FlightDepth::Partner(const CameraPoseSample& pose, double baseline_m) const {
  const MotionFrame* best = nullptr;
  double best_miss = std::numeric_limits<double>::infinity();
  for (const MotionFrame& kept : kept_) {
    if (!UsableBaseline(pose, kept.pose, stereo_)) continue;
    const double miss = std::abs((kept.pose.position - pose.position).norm() - baseline_m);
    if (miss < best_miss) best = &kept, best_miss = miss;
  }
  return best;
}

bool FlightDepth::Compute(const cv::Mat& image, const CameraPoseSample& pose, cv::Mat* depth_m, double* sigma_per_m2) {
  const TimestampNs horizon = SecondsToNs(flight_.history_s);
  while (!kept_.empty() && pose.timestamp_ns - kept_.front().pose.timestamp_ns > horizon) {
    spare_ = kept_.front().image;  // its buffer, reused by the next frame kept
    kept_.erase(kept_.begin());
  }
  depth_m->release();
  if (const MotionFrame* partner = Partner(pose, flight_.baseline_m)) {
    stereo_.matching.num_disparities = DisparitiesFor((partner->pose.position - pose.position).norm());
    *depth_m = PairDepth(image, *partner, lens_, pose, stereo_, sigma_per_m2);
  }
  MotionFrame kept{spare_, pose};
  spare_.release();
  image.copyTo(kept.image);
  kept_.push_back(std::move(kept));
  return !depth_m->empty();
}

}  // namespace patrolmap::depth
