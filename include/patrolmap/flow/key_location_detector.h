// Key-location detection from optical flow, paper 002 §III-A: per processed
// frame edges -> LK flow -> (de-rotation) -> polar transform -> hysteresis
// voting -> scene-flow response (equation 3) -> window smoothing -> peaks and
// valleys -> key locations.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"
#include "patrolmap/flow/edge_flow.h"
#include "patrolmap/flow/options.h"
#include "patrolmap/flow/polar_voting.h"
#include "patrolmap/flow/signal.h"

namespace patrolmap::flow {

// What the detector knows about the camera (from the log).
struct CameraContext {
  std::optional<CameraIntrinsics> camera;          // at the log's native resolution
  std::optional<Eigen::Matrix3d> camera_from_imu;  // needed for de-rotation
  double frame_rate_hz = 0.0;                      // the log's nominal rate [Hz]; 0 when unknown (FrameTiming)
};

// Frames smaller than this on a side once downscaled carry no usable flow: they are skipped and counted.
constexpr int kMinProcessedSide = 16;

// What one call produced; the detector appends, the caller clears.
struct DetectorOutput {
  std::vector<FlowSample> samples;         // processed frames whose smoothing is final
  std::vector<KeyLocation> key_locations;  // confirmed key locations
};

// Mean quantity of `accepted` vectors (equation 3) in image widths (per
// processed frame for kLength); NaN when none is accepted.
double SceneFlowResponse(const std::vector<PolarVector>& vectors, const std::vector<std::uint8_t>& accepted,
                         ResponseQuantity quantity, int image_width);

class KeyLocationDetector {
 public:
  // `options` must be valid (KeyLocationOptions::IsValid); checked here.
  KeyLocationDetector(const KeyLocationOptions& options, const CameraContext& context);

  // Whether the next frame given to Process() will be processed, so a reader
  // can skip decoding the others.
  bool NeedsImage() const { return frames_until_next_ == 0; }

  // Takes every frame of the log in order (skipped ones may come without an
  // image: their IMU samples still count).
  void Process(const Frame& frame, DetectorOutput* output);

  // Flushes the smoothing window at the end of the log.
  void Finish(DetectorOutput* output);

  // True when flow is de-rotated (option on, IMU extrinsics and intrinsics known).
  bool derotating() const { return derotate_; }
  int processed_frames() const { return processed_frames_; }
  // Frames due for processing that came without an image or too small to track (kMinProcessedSide).
  int unusable_frames() const { return unusable_frames_; }
  const FrameTiming& timing() const { return timing_; }
  // The image the last processed frame was tracked in (at the flow scale); valid until the next Process().
  const cv::Mat& last_image() const { return last_image_; }

 private:
  void ProcessSelected(const Frame& frame, DetectorOutput* output);
  bool Usable(const cv::Mat& image) const;  // grey, large enough, the size of the frames before it
  const cv::Mat& Downscale(const cv::Mat& image);
  void Derotate(TimestampNs timestamp_ns, int image_width);
  double ResponseOf(const Frame& frame, int image_width) const;
  void Emit(const FlowSample& sample, DetectorOutput* output);
  void DetectExtrema(DetectorOutput* output);  // runs the released samples through the extremum detector

  KeyLocationOptions options_;
  CameraContext context_;
  FrameTiming timing_;
  bool derotate_ = false;
  EdgeFlowTracker tracker_;
  std::optional<HysteresisVoter> voter_;
  WindowSmoother smoother_;
  ExtremumDetector extrema_;

  int frames_until_next_ = 0;
  int processed_frames_ = 0;
  int unusable_frames_ = 0;
  std::optional<TimestampNs> previous_processed_ns_;
  std::vector<ImuSample> pending_imu_;
  cv::Mat small_;
  cv::Mat last_image_;
  cv::Size last_size_;  // of the last processed frame, before downscaling
  std::vector<FlowVector> vectors_;
  std::vector<PolarVector> polar_;
  std::vector<std::uint8_t> accepted_;
  std::vector<FlowSample> released_;
};

}  // namespace patrolmap::flow
