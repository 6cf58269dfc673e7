// Sparse optical flow on edge pixels, paper 002 §III-A: Canny edge pixels,
// capped and spread over the image, tracked by pyramidal Lucas-Kanade into the
// next processed frame; and the de-rotation of that flow with gyro rates.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"
#include "patrolmap/flow/options.h"
#include "patrolmap/flow/polar_voting.h"

namespace patrolmap::flow {

// Picks up to options.max_points nonzero pixels of `edges`, sharing the cap
// evenly among the grid cells and spreading each cell's share over its edge
// pixels by a regular stride. Deterministic.
void SelectEdgePoints(const cv::Mat& edges, const EdgeOptions& options, std::vector<cv::Point2f>* points);

class EdgeFlowTracker {
 public:
  EdgeFlowTracker(const EdgeOptions& edges, const TrackerOptions& tracker);

  // Tracks the edge points of the previous image into `image` (CV_8UC1) and
  // writes one vector per successfully tracked point; then selects the edge
  // points of `image` for the next call. The first call yields no vectors.
  void Track(const cv::Mat& image, std::vector<FlowVector>* vectors);
  void Reset();
  // Edge points tracked in the last call (tracked or not).
  int last_point_count() const { return last_point_count_; }

 private:
  int CellOf(const cv::Point2f& point, const cv::Size& size) const;
  void UpdatePrediction(const std::vector<FlowVector>& vectors, const cv::Size& size);
  void PredictPositions(const cv::Size& size);
  void CheckForwardBackward(const cv::TermCriteria& criteria);

  EdgeOptions edge_options_;
  TrackerOptions tracker_options_;
  std::vector<cv::Mat> previous_pyramid_;
  std::vector<cv::Mat> current_pyramid_;
  std::vector<cv::Point2f> previous_points_;
  std::vector<cv::Point2f> tracked_points_;
  std::vector<unsigned char> track_status_;
  std::vector<cv::Point2f> back_points_;
  std::vector<unsigned char> back_status_;
  std::vector<float> track_errors_;
  cv::Mat edges_;
  int last_point_count_ = 0;
  std::vector<cv::Point2f> cell_flow_;                 // predicted flow per edge-grid cell
  std::vector<std::vector<float>> cell_dx_, cell_dy_;  // scratch for the medians
  bool has_prediction_ = false;
};

// Rotation of the camera between two instants from gyro samples in the IMU
// frame: returns R such that a direction d1 in the later camera frame is
// R * d1 in the earlier one. Samples cover (start_ns, end_ns]; each holds its
// rate over the interval that ends at its timestamp.
Eigen::Matrix3d IntegrateGyro(const std::vector<ImuSample>& samples, TimestampNs start_ns, TimestampNs end_ns,
                              const Eigen::Matrix3d& camera_from_imu);

// Removes the flow a pure rotation would cause: for a vector from p0 to p1 the
// result runs from p0 to p1 - (H p0 - p0), with H = K R^T K^-1 the homography
// of the rotation `earlier_from_later` and K the intrinsics at image scale.
void DerotateFlow(const CameraIntrinsics& camera, const Eigen::Matrix3d& earlier_from_later,
                  std::vector<FlowVector>* vectors);

}  // namespace patrolmap::flow
