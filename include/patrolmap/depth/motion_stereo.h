// Motion stereo (DESIGN.md, depth): one camera seen from two poses of the same flight is a stereo pair whose
// calibration is the relative pose between them. The pair is matched as depth::StereoDepth matches a rig (the
// relative pose as its calibration, semi-global matching), turned first so that the other camera stands to the right
// whichever way across the optical axis the flight moved it. A camera looking sideways from a UAV at 1.3 m/s gets a
// baseline of 1.3 m from two frames a second apart, ten times a small stereo rig's, and so ranges facades a rig cannot.
//
// Used by the route's appearance check (change/route_depth.h: the frames before and after a route frame) and by the
// evidence grid's depth from the flight (FlightDepth below: earlier frames of the flight, chosen for their baseline).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"
#include "patrolmap/depth/lens.h"
#include "patrolmap/depth/options.h"

namespace patrolmap::depth {

// The rigid motion taking points from the axes of a camera at `from` into those of a camera at `into`:
// into.ToCamera(from.ToWorld(p)) as one matrix and one offset, for loops over every pixel.
struct RelativePose {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  RelativePose(const CameraPoseSample& from, const CameraPoseSample& into)
      : rotation((into.rotation.conjugate() * from.rotation).toRotationMatrix()),
        translation(into.ToCamera(from.position)) {}
};

// Another frame of the same camera: its grey image (the frame's size) and its pose.
struct MotionFrame {
  cv::Mat image;
  CameraPoseSample pose;
};

struct MotionStereoOptions {
  double min_baseline_m = 0.3;      // frames closer together than this give no depth [m]
  double min_sideways_share = 0.7;  // ... nor frames whose baseline runs less than this share across the optical axis
  StereoOptions matching;           // how the pair is matched (num_disparities, block_size, disparity_sigma_px, ...)
  // Two pairs' depths of one pixel agree within the larger of agree_m and agree_sigmas times their range errors, and
  // are averaged; where they disagree (a repeated texture matched a wrong period) the pixel is left unknown.
  double agree_m = 0.5;
  double agree_sigmas = 3.0;
};

// Whether `other` stands far enough from `pose` and across its optical axis to be matched with it.
bool UsableBaseline(const CameraPoseSample& pose, const CameraPoseSample& other, const MotionStereoOptions& options);

// Depth [m] along the optical axis of the frame `image` (grey, the lens's size) seen from `pose`, on the lens's
// undistorted grid (0 = unknown), from each of `others` with a usable baseline, fused where two give depth; the range
// error per squared metre of the least precise pair into `sigma_per_m2`. Empty when none gives depth.
cv::Mat MotionDepth(const cv::Mat& image, const CameraPoseSample& pose, const std::vector<MotionFrame>& others,
                    const Lens& lens, const MotionStereoOptions& options, double* sigma_per_m2);

// Depth from the flight for the evidence grid (depth.source flight): keeps the last frames handed to it over
// `FlightDepthOptions::history_s`, and gives each new frame depth from the earlier one whose sideways baseline comes
// nearest `FlightDepthOptions::baseline_m` (a farther facade needs a longer one: the range error at depth z is z^2 s /
// (f b)). Only past frames are used, so it runs while flying; its buffers are reused from frame to frame.
class FlightDepth {
 public:
  // Pairs matched with `matching` (depth.stereo's options) over the disparity range DisparitiesFor() their baseline.
  FlightDepth(const Lens& lens, const FlightDepthOptions& flight, const StereoOptions& matching);

  // Depth of `image` (grey, the lens's size) seen from `pose` into `depth_m` (the undistorted grid, 0 = unknown) and
  // its range error per squared metre into `sigma_per_m2`; false, `depth_m` left empty, when no kept frame stands
  // usably far. Frames kept longer than history_s before `pose` are dropped first; then the frame is kept.
  bool Compute(const cv::Mat& image, const CameraPoseSample& pose, cv::Mat* depth_m, double* sigma_per_m2);
  // The range error per squared metre of a pair `baseline_m` apart.
  double SigmaPerM2(double baseline_m) const;
  // The disparity range [px] a pair `baseline_m` apart is searched over: f * b / min_range_m, a multiple of 16.
  int DisparitiesFor(double baseline_m) const;
  // The nearest depth [m] it matches: f * b / DisparitiesFor(b) (min_range_m, or a little nearer).
  double NearestDepth(double baseline_m) const;

 private:
  Lens lens_;
  FlightDepthOptions flight_;
  MotionStereoOptions stereo_;
  std::vector<MotionFrame> kept_;  // oldest first; images reused when dropped
  // The kept frame usable with `pose` whose distance comes nearest `baseline_m`; null when none.
  const MotionFrame* Partner(const CameraPoseSample& pose, double baseline_m) const;

  cv::Mat spare_;  // the image of the last frame dropped, its buffer reused
};

}  // namespace patrolmap::depth
