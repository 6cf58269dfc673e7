#include "patrolmap/depth/stereo.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

namespace patrolmap::depth {

// Buffers of one matching, reused from frame to frame.
struct MatchBuffers {
  cv::Mat padded_left, padded_right, padded_disparity, flipped_left, flipped_right, right_view, local_max, local_min,
      unknown, shifted_right, second;
  cv::Mat half_left, half_right, half_disparity;  // StereoOptions::near_pass: the pair at half resolution, ...
  std::unique_ptr<MatchBuffers> half;             // ... matched with buffers of its own (its sizes differ)
};

namespace {

cv::Mat CameraMatrix(const CameraIntrinsics& camera) {
  return (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
}

cv::Mat Distortion(const std::array<double, 4>& coefficients) {
  return (cv::Mat_<double>(1, 4) << coefficients[0], coefficients[1], coefficients[2], coefficients[3]);
}

cv::Ptr<cv::StereoSGBM> CreateMatcher(const StereoOptions& options) {
  const int area = options.block_size * options.block_size;
  return cv::StereoSGBM::create(0, options.num_disparities, options.block_size, 8 * area, 32 * area, -1, 0,
                                options.uniqueness_ratio, options.speckle_window, options.speckle_range,
                                options.full_paths ? cv::StereoSGBM::MODE_HH : cv::StereoSGBM::MODE_SGBM_3WAY);
}

// SGBM leaves the first num_disparities columns of the left view unmatched (their search would leave the
// image). Both images are padded on the left by that many replicated columns, so every real column gets a
// disparity; those pointing into the padding fail the left-right check.
void MatchPadded(cv::StereoSGBM* matcher, const cv::Mat& left, const cv::Mat& right, int pad, MatchBuffers* buffers,
                 cv::Mat* disparity) {
  cv::copyMakeBorder(left, buffers->padded_left, 0, 0, pad, 0, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(right, buffers->padded_right, 0, 0, pad, 0, cv::BORDER_REPLICATE);
  matcher->compute(buffers->padded_left, buffers->padded_right, buffers->padded_disparity);
  buffers->padded_disparity.colRange(pad, buffers->padded_disparity.cols).copyTo(*disparity);
}

// The right image sampled `shift` pixels further along its rows: its disparities against the left one grow by
// `shift`.
void ShiftRows(const cv::Mat& right, double shift, cv::Mat* shifted) {
  const cv::Matx23d m(1, 0, shift, 0, 1, 0);
  cv::warpAffine(right, *shifted, m, right.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
}

// SGBM's sub-pixel fit pulls a disparity towards whole pixels, by an amount that depends on its fraction and
// changes sign half a pixel on. The pair is matched with the right image shifted by +1/4 and -1/4 px: the two
// disparities lie half a pixel apart, so their pulls are about opposite, and their mean keeps what is left of
// it. Where the two disagree by more than max_lr_difference (beyond the half pixel) the disparity is unknown.
void MatchCancelled(cv::StereoSGBM* matcher, const cv::Mat& left, const cv::Mat& right, const StereoOptions& options,
                    MatchBuffers* buffers, cv::Mat* disparity) {
  constexpr double kQuarter = 0.25;
  const int scale = cv::StereoMatcher::DISP_SCALE;
  ShiftRows(right, kQuarter, &buffers->shifted_right);
  MatchPadded(matcher, left, buffers->shifted_right, options.num_disparities, buffers, disparity);
  ShiftRows(right, -kQuarter, &buffers->shifted_right);
  MatchPadded(matcher, left, buffers->shifted_right, options.num_disparities, buffers, &buffers->second);
  const int apart = static_cast<int>(std::lround(2 * kQuarter * scale));
  const double tolerance = options.max_lr_difference * scale;
  for (int y = 0; y < disparity->rows; ++y) {
    std::int16_t* plus = disparity->ptr<std::int16_t>(y);
    const std::int16_t* minus = buffers->second.ptr<std::int16_t>(y);
    for (int x = 0; x < disparity->cols; ++x) {
      const bool both = plus[x] > apart && minus[x] > 0;
      plus[x] = both && std::abs(plus[x] - minus[x] - apart) <= tolerance
                    ? static_cast<std::int16_t>((plus[x] + minus[x] + 1) / 2)
                    : -1;
    }
  }
}

// Keeps a left disparity only where the right view's (matched with the pair mirrored), at the pixel it points to,
// agrees within max_lr_difference.
void CheckLeftRight(cv::StereoSGBM* matcher, const cv::Mat& left, const cv::Mat& right, const StereoOptions& options,
                    MatchBuffers* buffers, cv::Mat* disparity) {
  cv::flip(left, buffers->flipped_left, 1);
  cv::flip(right, buffers->flipped_right, 1);
  // Mirrored: column w-1-x of the result is column x of the right view.
  MatchPadded(matcher, buffers->flipped_right, buffers->flipped_left, options.num_disparities, buffers,
              &buffers->right_view);
  const int scale = cv::StereoMatcher::DISP_SCALE;
  const double tolerance = options.max_lr_difference * scale;
  const int width = disparity->cols;
  for (int y = 0; y < disparity->rows; ++y) {
    std::int16_t* d = disparity->ptr<std::int16_t>(y);
    const std::int16_t* mirrored = buffers->right_view.ptr<std::int16_t>(y);
    for (int x = 0; x < width; ++x) {
      if (d[x] <= 0) continue;
      const int xr = x - (d[x] + scale / 2) / scale;
      const std::int16_t back = xr >= 0 ? mirrored[width - 1 - xr] : -1;
      if (back <= 0 || std::abs(back - d[x]) > tolerance) d[x] = -1;
    }
  }
}

// Leaves unknown every disparity (CV_16S fixed point) whose (2 radius + 1)^2 window holds known disparities
// differing by more than jump_px: a depth edge, where SGBM's aggregated costs mix the two surfaces.
void DropDepthEdges(int radius, double jump_px, MatchBuffers* buffers, cv::Mat* disparity) {
  if (radius <= 0) return;
  // A 3x3 square applied `radius` times is the (2 radius + 1)^2 square, with no kernel made per frame.
  const cv::Point centre(-1, -1);
  cv::dilate(*disparity, buffers->local_max, cv::Mat(), centre, radius);  // unknown (0 or below) never wins
  disparity->copyTo(buffers->local_min);
  cv::compare(*disparity, 0, buffers->unknown, cv::CMP_LE);
  buffers->local_min.setTo(std::numeric_limits<std::int16_t>::max(), buffers->unknown);
  cv::erode(buffers->local_min, buffers->local_min, cv::Mat(), centre, radius);
  const int jump = static_cast<int>(std::lround(jump_px * cv::StereoMatcher::DISP_SCALE));
  for (int y = 0; y < disparity->rows; ++y) {
    std::int16_t* d = disparity->ptr<std::int16_t>(y);
    const std::int16_t* high = buffers->local_max.ptr<std::int16_t>(y);
    const std::int16_t* low = buffers->local_min.ptr<std::int16_t>(y);
    for (int x = 0; x < disparity->cols; ++x) {
      if (d[x] > 0 && high[x] - low[x] > jump) d[x] = -1;
    }
  }
}

// Disparity of the left view in SGBM's fixed point (CV_16S, 1/16 px; 0 or below: none), left-right checked
// (CheckLeftRight) and with depth edges dropped (DropDepthEdges) as the options ask.
void MatchPair(cv::StereoSGBM* matcher, const cv::Mat& left, const cv::Mat& right, const StereoOptions& options,
               MatchBuffers* buffers, cv::Mat* disparity) {
  if (options.cancel_pixel_locking) {
    MatchCancelled(matcher, left, right, options, buffers, disparity);
  } else {
    MatchPadded(matcher, left, right, options.num_disparities, buffers, disparity);
  }
  if (options.lr_check) CheckLeftRight(matcher, left, right, options, buffers, disparity);
  DropDepthEdges(options.edge_radius_px, options.edge_jump_px, buffers, disparity);
}

// Where the half-resolution disparity `half` (fixed point, of the pair pyrDown'd), doubled, lies beyond the
// range of `disparity` (the full resolution's, num_disparities wide), it stands in for it: a surface nearer than
// the full range reaches, which the full resolution cannot have matched right.
void TakeNearHalf(const cv::Mat& half, int num_disparities, cv::Mat* disparity) {
  const int beyond = (num_disparities - 1) * cv::StereoMatcher::DISP_SCALE;
  for (int y = 0; y < disparity->rows; ++y) {
    std::int16_t* d = disparity->ptr<std::int16_t>(y);
    const std::int16_t* h = half.ptr<std::int16_t>(std::min(y / 2, half.rows - 1));
    for (int x = 0; x < disparity->cols; ++x) {
      const int doubled = 2 * h[std::min(x / 2, half.cols - 1)];
      if (doubled >= beyond) d[x] = static_cast<std::int16_t>(doubled);
    }
  }
}

// MatchPair, and with options.near_pass the same at half resolution standing in where it lies beyond the range.
void MatchRectified(cv::StereoSGBM* matcher, const cv::Mat& left, const cv::Mat& right, const StereoOptions& options,
                    MatchBuffers* buffers, cv::Mat* disparity) {
  MatchPair(matcher, left, right, options, buffers, disparity);
  if (!options.near_pass) return;
  if (buffers->half == nullptr) buffers->half = std::make_unique<MatchBuffers>();
  cv::pyrDown(left, buffers->half_left);
  cv::pyrDown(right, buffers->half_right);
  MatchPair(matcher, buffers->half_left, buffers->half_right, options, buffers->half.get(), &buffers->half_disparity);
  TakeNearHalf(buffers->half_disparity, options.num_disparities, disparity);
}

// Left pinhole grid -> rectified left pixel, and the factor turning a rectified depth into a left one.
void BackMaps(const CameraIntrinsics& left, const cv::Mat& rotation, const cv::Mat& projection, cv::Mat* map_x,
              cv::Mat* map_y, cv::Mat* scale) {
  map_x->create(left.height, left.width, CV_32F);
  map_y->create(left.height, left.width, CV_32F);
  scale->create(left.height, left.width, CV_32F);
  const cv::Matx33d r(rotation);
  const double fx = projection.at<double>(0, 0), fy = projection.at<double>(1, 1);
  const double cx = projection.at<double>(0, 2), cy = projection.at<double>(1, 2);
  for (int v = 0; v < left.height; ++v) {
    for (int u = 0; u < left.width; ++u) {
      const cv::Vec3d ray = r * cv::Vec3d((u - left.cx) / left.fx, (v - left.cy) / left.fy, 1.0);
      const bool ahead = ray[2] > 1e-6;
      map_x->at<float>(v, u) = ahead ? static_cast<float>(fx * ray[0] / ray[2] + cx) : -1.0f;
      map_y->at<float>(v, u) = ahead ? static_cast<float>(fy * ray[1] / ray[2] + cy) : -1.0f;
      scale->at<float>(v, u) = ahead ? static_cast<float>(1.0 / ray[2]) : 0.0f;
    }
  }
}

}  // namespace

void ComputeDisparity(const cv::Mat& left, const cv::Mat& right, const StereoOptions& options, cv::Mat* disparity) {
  cv::Mat fixed_point;
  MatchBuffers buffers;
  MatchRectified(CreateMatcher(options).get(), left, right, options, &buffers, &fixed_point);
  fixed_point.convertTo(*disparity, CV_32F, 1.0 / cv::StereoMatcher::DISP_SCALE);
}

Status StereoDepth::Create(const StereoCalibration& calibration, const StereoOptions& options,
                           std::unique_ptr<StereoDepth>* stereo) {
  std::string error;
  if (!options.IsValid(&error)) return Status::InvalidArgument(error);
  if (!calibration.left.valid() || !calibration.right.valid()) {
    return Status::InvalidArgument("stereo pair: a camera has no valid intrinsics or resolution");
  }
  const double baseline = calibration.right_from_left_translation.norm();
  if (!(baseline > 1e-4))
    return Status::InvalidArgument("stereo pair: the cameras are at the same place (no baseline)");
  std::unique_ptr<StereoDepth> result(new StereoDepth());
  result->options_ = options;
  result->left_size_ = cv::Size(calibration.left.width, calibration.left.height);
  result->right_size_ = cv::Size(calibration.right.width, calibration.right.height);
  result->rectified_size_ = result->left_size_;
  cv::Mat rotation, translation;
  cv::eigen2cv(calibration.right_from_left_rotation, rotation);
  cv::eigen2cv(calibration.right_from_left_translation, translation);
  const cv::Mat k_left = CameraMatrix(calibration.left), k_right = CameraMatrix(calibration.right);
  const cv::Mat d_left = Distortion(calibration.left_distortion), d_right = Distortion(calibration.right_distortion);
  cv::Mat r_left, r_right, p_left, p_right, q;
  cv::stereoRectify(k_left, d_left, k_right, d_right, result->left_size_, rotation, translation, r_left, r_right,
                    p_left, p_right, q, cv::CALIB_ZERO_DISPARITY, 0.0, result->rectified_size_);
  // Side by side: the right camera's projection shifts x only (a vertical pair would shift y).
  if (std::abs(p_right.at<double>(1, 3)) > 1e-6 * std::abs(p_right.at<double>(0, 3))) {
    return Status::InvalidArgument(
        "stereo pair: the cameras are one above the other; only side-by-side pairs are matched");
  }
  result->focal_px_ = p_left.at<double>(0, 0);
  result->baseline_m_ = std::abs(p_right.at<double>(0, 3) / p_right.at<double>(0, 0));
  result->range_sigma_per_m2_ = options.disparity_sigma_px / (result->focal_px_ * result->baseline_m_);
  cv::initUndistortRectifyMap(k_left, d_left, r_left, p_left, result->rectified_size_, CV_16SC2, result->left_map_x_,
                              result->left_map_y_);
  cv::initUndistortRectifyMap(k_right, d_right, r_right, p_right, result->rectified_size_, CV_16SC2,
                              result->right_map_x_, result->right_map_y_);
  BackMaps(calibration.left, r_left, p_left, &result->back_x_, &result->back_y_, &result->back_scale_);
  result->matcher_ = CreateMatcher(options);
  result->buffers_ = std::make_unique<MatchBuffers>();
  *stereo = std::move(result);
  return Status::Ok();
}

double StereoDepth::DepthWithin(double sigma_m) const {
  if (range_sigma_per_m2_ <= 0.0) return std::numeric_limits<double>::infinity();
  return std::sqrt(std::max(0.0, sigma_m) / range_sigma_per_m2_);
}

double StereoDepth::NearestDepth() const {
  const int reach = options_.near_pass ? 2 * options_.num_disparities : options_.num_disparities;
  return std::max(focal_px_ * baseline_m_ / reach, options_.min_range_m);
}

StereoDepth::~StereoDepth() = default;

Status StereoDepth::Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* depth_m) {
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    return Status::InvalidArgument("stereo pair: images must be 8-bit grey");
  }
  if (left.size() != left_size_ || right.size() != right_size_) {
    return Status::InvalidArgument(
        "stereo pair: images are " + std::to_string(left.cols) + "x" + std::to_string(left.rows) + " and " +
        std::to_string(right.cols) + "x" + std::to_string(right.rows) + ", the calibration says " +
        std::to_string(left_size_.width) + "x" + std::to_string(left_size_.height) + " and " +
        std::to_string(right_size_.width) + "x" + std::to_string(right_size_.height));
  }
  cv::remap(left, left_rectified_, left_map_x_, left_map_y_, cv::INTER_LINEAR);
  cv::remap(right, right_rectified_, right_map_x_, right_map_y_, cv::INTER_LINEAR);
  MatchRectified(matcher_.get(), left_rectified_, right_rectified_, options_, buffers_.get(), &disparity_);
  // Rectified depth f * b / d, unknown outside the range (and where no disparity was found).
  rectified_depth_.create(disparity_.size(), CV_32F);
  const double focal_baseline = focal_px_ * baseline_m_ * cv::StereoMatcher::DISP_SCALE;
  for (int y = 0; y < disparity_.rows; ++y) {
    const std::int16_t* d = disparity_.ptr<std::int16_t>(y);
    float* z = rectified_depth_.ptr<float>(y);
    for (int x = 0; x < disparity_.cols; ++x) {
      const double range = d[x] > 0 ? focal_baseline / d[x] : 0.0;
      z[x] = range >= options_.min_range_m && range <= options_.max_range_m ? static_cast<float>(range) : 0.0f;
    }
  }
  cv::remap(rectified_depth_, *depth_m, back_x_, back_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::multiply(*depth_m, back_scale_, *depth_m);
  return Status::Ok();
}

}  // namespace patrolmap::depth
