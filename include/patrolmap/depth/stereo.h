// Depth from a calibrated stereo pair (DESIGN.md, depth): the pair is rectified with maps computed once
// (OpenCV stereoRectify, initUndistortRectifyMap), matched by semi-global matching (StereoSGBM: a left-right
// consistency check, speckle filtering, uniqueness), and the disparity turned into depth along the left
// camera's optical axis on the left camera's pinhole image grid, so it feeds the evidence grid and object
// segmentation exactly as a depth0/ image does.
//
// Stereo depth is uncertain: with disparity noise s [px], focal length f [px] and baseline b [m] the
// range error at depth z grows as z^2 * s / (f * b) (RangeSigma); the evidence grid keeps its free-space
// carving that far in front of each return.
#pragma once

#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"
#include "patrolmap/depth/options.h"

namespace cv {
class StereoSGBM;
}

namespace patrolmap::depth {

struct MatchBuffers;

// Disparity of the left view [px] from rectified grey images (CV_32F; unmatched pixels below 0).
void ComputeDisparity(const cv::Mat& left, const cv::Mat& right, const StereoOptions& options, cv::Mat* disparity);

class StereoDepth {
 public:
  // Fails naming the problem when the pair cannot be rectified side by side (no baseline, cameras one
  // above the other) or the options are invalid.
  static Status Create(const StereoCalibration& calibration, const StereoOptions& options,
                       std::unique_ptr<StereoDepth>* stereo);

  // Depth [m] along the left camera's optical axis for each pixel of the left camera's undistorted image
  // (CV_32F, calibration.left's size; 0 = unknown) from the raw grey images of the pair.
  Status Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* depth_m);
  ~StereoDepth();
  StereoDepth(const StereoDepth&) = delete;
  StereoDepth& operator=(const StereoDepth&) = delete;

  // The range error expected at depth `z_m` [m].
  double RangeSigma(double z_m) const { return z_m * z_m * range_sigma_per_m2_; }
  // The depth [m] up to which the range error stays within `sigma_m` (RangeSigma's inverse).
  double DepthWithin(double sigma_m) const;
  // The nearest depth [m] the disparity range reaches, f * b / num_disparities (half that with near_pass): nearer
  // surfaces get no depth.
  double NearestDepth() const;
  double baseline_m() const { return baseline_m_; }
  double focal_px() const { return focal_px_; }

 private:
  StereoDepth() = default;

  StereoOptions options_;
  cv::Size left_size_, right_size_, rectified_size_;
  cv::Mat left_map_x_, left_map_y_, right_map_x_, right_map_y_;  // raw -> rectified
  cv::Mat back_x_, back_y_, back_scale_;  // left pinhole grid -> rectified pixel, rectified z -> left z
  double baseline_m_ = 0.0, focal_px_ = 0.0, range_sigma_per_m2_ = 0.0;
  cv::Ptr<cv::StereoSGBM> matcher_;
  std::unique_ptr<MatchBuffers> buffers_;
  cv::Mat left_rectified_, right_rectified_, disparity_, rectified_depth_;  // reused buffers
};

}  // namespace patrolmap::depth
