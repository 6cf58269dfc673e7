// A camera's raw images through its lens: pinhole intrinsics with radial-tangential distortion (core/types.h,
// Distortion). Depth from stereo comes on the undistorted (pinhole) grid of the same intrinsics; a raw image's pixel
// finds its place there with pinhole_at(), and a point in camera axes finds its raw pixel with Project().
#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"

namespace patrolmap::depth {

class Lens {
 public:
  Lens() = default;
  // Without distortion nothing is computed; with it, each pixel's undistorted place (cv::undistortPoints, once).
  explicit Lens(const CameraIntrinsics& camera, const Distortion& distortion = {});

  const CameraIntrinsics& camera() const { return camera_; }
  const Distortion& distortion() const { return distortion_; }
  bool distorted() const { return !pinhole_at_.empty(); }

  // Each raw pixel's position on the undistorted grid (CV_32FC2, for cv::remap); empty when not distorted.
  const cv::Mat& pinhole_at() const { return pinhole_at_; }

  // The ray (x, y, 1) through raw pixel (u, v), in camera axes.
  Eigen::Vector3d Ray(int u, int v) const;

  // Where `point` (camera axes) lands on the raw image; false behind the camera, or, through a distorting lens,
  // beyond the widest ray the image holds (where the distortion polynomial folds back).
  bool Project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const;

  // An image on the undistorted grid (depth from stereo) brought onto the raw grid: each raw pixel takes the value
  // nearest its undistorted place, 0 where that lies off the grid. `pinhole` itself when the lens does not distort.
  cv::Mat ToRaw(const cv::Mat& pinhole) const;

 private:
  CameraIntrinsics camera_;
  Distortion distortion_{};
  cv::Mat pinhole_at_;
  double widest_squared_ = 0.0;  // the largest x^2 + y^2 of any pixel's ray
};

// The distortion of the same lens when its image is mirrored left to right, transposed, or turned a quarter
// clockwise (u' = height - 1 - v, v' = u): the radial terms stay, the tangential ones swap or change sign.
Distortion MirroredDistortion(const Distortion& d);
Distortion TransposedDistortion(const Distortion& d);
Distortion TurnedDistortion(const Distortion& d);

}  // namespace patrolmap::depth
