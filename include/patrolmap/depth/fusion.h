// Multi-frame fusion of stereo depth (DESIGN.md, depth): one pair's range error grows with the square of the depth
// (StereoDepth::RangeSigma), so past some distance a single return is too uncertain to mark a surface. A flight sees
// the same surface from several poses; where the depth frames before agree with a return, their depths (moved into
// the current camera with the poses) are averaged with it, and the range error of the mean falls with the number
// of views. Not all of it: frames that see a surface from nearly the same distance share part of their matching
// error (SGBM's pull towards whole pixels, a textureless patch filled in alike), and averaging leaves that part.
// So the error of a mean of n views is sigma * sqrt(shared + (1 - shared) / n), `shared` the share of a frame's
// error variance the frames have in common.
//
// Only the pixels the evidence grid traces are fused (every `step` pixels from step / 2 in both directions). The
// frames kept are the raw ones, so no noise is counted twice.
#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"

namespace patrolmap::depth {

struct FusionOptions {
  int frames = 0;                   // earlier depth frames fused with each one; 0: no fusion
  double gate_sigmas = 2.0;         // an earlier frame agrees when its depth is within this many combined range errors
  double range_sigma_per_m2 = 0.0;  // the range error at depth z is this * z^2 [m] (StereoDepth::RangeSigma(1))
  double shared_variance = 0.0;     // share of a frame's error variance common to the frames fused, in [0, 1]
};

class DepthFusion {
 public:
  DepthFusion(const CameraIntrinsics& camera, const FusionOptions& options);

  // Fuses the pixels on the lattice `step` of `depth_m` (CV_32F along the optical axis, 0 = no return; the camera's
  // size) seen from `pose` with the frames kept, in place; `error_scale` (CV_32F, same size) gets at each lattice
  // pixel the factor ErrorScale(views) of the fused depth's range error (1: this frame alone; 0: no return). Then
  // keeps the raw frame, dropping the oldest.
  void Fuse(const CameraPoseSample& pose, int step, cv::Mat* depth_m, cv::Mat* error_scale);
  // The range error of a mean of `views` agreeing depths, as a share of one depth's.
  double ErrorScale(int views) const;

 private:
  struct Kept {
    cv::Mat depth_m;
    CameraPoseSample pose;
  };
  // The depth along the current optical axis of the surface frame `kept` saw where `world` projects, if any.
  bool DepthSeenBy(const Kept& kept, const Eigen::Vector3d& world, const CameraPoseSample& pose, double* z) const;
  double Sigma(double z) const { return options_.range_sigma_per_m2 * z * z; }
  // The point at depth `z` along pixel (u, v)'s ray, in the camera.
  Eigen::Vector3d InCamera(double u, double v, double z) const {
    return {z * (u - camera_.cx) / camera_.fx, z * (v - camera_.cy) / camera_.fy, z};
  }

  CameraIntrinsics camera_;
  FusionOptions options_;
  std::vector<Kept> kept_;     // a ring of options.frames, newest at next_ - 1
  std::vector<float> scales_;  // ErrorScale of each number of views
  cv::Mat raw_;                // the current frame before fusion
  int next_ = 0, count_ = 0;
};

}  // namespace patrolmap::depth
