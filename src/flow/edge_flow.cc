#include "patrolmap/flow/edge_flow.h"

#include <algorithm>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace patrolmap::flow {
namespace {

float Median(std::vector<float>* values) {
  std::nth_element(values->begin(), values->begin() + values->size() / 2, values->end());
  return (*values)[values->size() / 2];
}

void SelectInCell(const cv::Mat& edges, const cv::Rect& cell, int quota, std::vector<cv::Point2f>* points) {
  const int count = cv::countNonZero(edges(cell));
  if (count == 0 || quota <= 0) return;
  const int stride = std::max(1, count / quota);
  int seen = 0, taken = 0;
  for (int y = cell.y; y < cell.y + cell.height && taken < quota; ++y) {
    const unsigned char* row = edges.ptr<unsigned char>(y);
    for (int x = cell.x; x < cell.x + cell.width; ++x) {
      if (row[x] == 0) continue;
      if (seen++ % stride != 0) continue;
      points->emplace_back(static_cast<float>(x), static_cast<float>(y));
      if (++taken == quota) break;
    }
  }
}

}  // namespace

void SelectEdgePoints(const cv::Mat& edges, const EdgeOptions& options, std::vector<cv::Point2f>* points) {
  points->clear();
  const cv::Rect inner(options.border, options.border, edges.cols - 2 * options.border,
                       edges.rows - 2 * options.border);
  if (inner.width <= 0 || inner.height <= 0) return;
  const int cells = options.grid_columns * options.grid_rows;
  const int quota = std::max(1, options.max_points / cells);
  for (int row = 0; row < options.grid_rows; ++row) {
    for (int column = 0; column < options.grid_columns; ++column) {
      const int x0 = inner.x + inner.width * column / options.grid_columns;
      const int x1 = inner.x + inner.width * (column + 1) / options.grid_columns;
      const int y0 = inner.y + inner.height * row / options.grid_rows;
      const int y1 = inner.y + inner.height * (row + 1) / options.grid_rows;
      SelectInCell(edges, cv::Rect(x0, y0, x1 - x0, y1 - y0), quota, points);
    }
  }
}

EdgeFlowTracker::EdgeFlowTracker(const EdgeOptions& edges, const TrackerOptions& tracker)
    : edge_options_(edges), tracker_options_(tracker) {
  const int cells = edges.grid_columns * edges.grid_rows + 1;  // the last one is the whole image
  cell_flow_.assign(cells, cv::Point2f(0.0f, 0.0f));
  cell_dx_.resize(cells);
  cell_dy_.resize(cells);
}

void EdgeFlowTracker::Reset() {
  previous_pyramid_.clear();
  previous_points_.clear();
  has_prediction_ = false;
}

int EdgeFlowTracker::CellOf(const cv::Point2f& point, const cv::Size& size) const {
  const int column = std::clamp(static_cast<int>(point.x * edge_options_.grid_columns / size.width), 0,
                                edge_options_.grid_columns - 1);
  const int row =
      std::clamp(static_cast<int>(point.y * edge_options_.grid_rows / size.height), 0, edge_options_.grid_rows - 1);
  return row * edge_options_.grid_columns + column;
}

// Median flow per cell of the vectors that end in it (where the next frame's points start).
void EdgeFlowTracker::UpdatePrediction(const std::vector<FlowVector>& vectors, const cv::Size& size) {
  const int all = static_cast<int>(cell_flow_.size()) - 1;
  for (std::size_t cell = 0; cell < cell_flow_.size(); ++cell) cell_dx_[cell].clear(), cell_dy_[cell].clear();
  for (const FlowVector& vector : vectors) {
    const int cell = CellOf(vector.start + vector.delta, size);
    for (int target : {cell, all}) {
      cell_dx_[target].push_back(vector.delta.x);
      cell_dy_[target].push_back(vector.delta.y);
    }
  }
  has_prediction_ = !cell_dx_[all].empty();
  if (!has_prediction_) return;
  const cv::Point2f global(Median(&cell_dx_[all]), Median(&cell_dy_[all]));
  for (int cell = 0; cell < all; ++cell) {
    cell_flow_[cell] = cell_dx_[cell].empty() ? global : cv::Point2f(Median(&cell_dx_[cell]), Median(&cell_dy_[cell]));
  }
}

void EdgeFlowTracker::PredictPositions(const cv::Size& size) {
  tracked_points_.resize(previous_points_.size());
  for (std::size_t i = 0; i < previous_points_.size(); ++i) {
    tracked_points_[i] = previous_points_[i] + cell_flow_[CellOf(previous_points_[i], size)];
  }
}

void EdgeFlowTracker::Track(const cv::Mat& image, std::vector<FlowVector>* vectors) {
  vectors->clear();
  const cv::Size window(tracker_options_.window_size, tracker_options_.window_size);
  cv::buildOpticalFlowPyramid(image, current_pyramid_, window, tracker_options_.pyramid_levels);
  last_point_count_ = static_cast<int>(previous_points_.size());
  if (!previous_points_.empty()) {
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, tracker_options_.max_iterations,
                                    tracker_options_.epsilon);
    const bool predict = tracker_options_.predict_from_previous && has_prediction_;
    if (predict) PredictPositions(image.size());
    cv::calcOpticalFlowPyrLK(previous_pyramid_, current_pyramid_, previous_points_, tracked_points_, track_status_,
                             track_errors_, window, tracker_options_.pyramid_levels, criteria,
                             predict ? cv::OPTFLOW_USE_INITIAL_FLOW : 0, tracker_options_.min_eigen_threshold);
    if (tracker_options_.max_forward_backward_px > 0.0) CheckForwardBackward(criteria);
    for (std::size_t i = 0; i < previous_points_.size(); ++i) {
      if (track_status_[i]) vectors->push_back({previous_points_[i], tracked_points_[i] - previous_points_[i]});
    }
    UpdatePrediction(*vectors, image.size());
  }
  cv::Canny(image, edges_, edge_options_.canny_low, edge_options_.canny_high);
  SelectEdgePoints(edges_, edge_options_, &previous_points_);
  std::swap(previous_pyramid_, current_pyramid_);
}

// Tracks the found points back into the previous image and clears the status
// of those that do not return close to where they started.
void EdgeFlowTracker::CheckForwardBackward(const cv::TermCriteria& criteria) {
  const cv::Size window(tracker_options_.window_size, tracker_options_.window_size);
  back_points_ = previous_points_;  // the start is the natural first guess
  cv::calcOpticalFlowPyrLK(current_pyramid_, previous_pyramid_, tracked_points_, back_points_, back_status_,
                           track_errors_, window, tracker_options_.pyramid_levels, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW, tracker_options_.min_eigen_threshold);
  const double limit = tracker_options_.max_forward_backward_px;
  for (std::size_t i = 0; i < previous_points_.size(); ++i) {
    const cv::Point2f miss = back_points_[i] - previous_points_[i];
    if (!back_status_[i] || miss.dot(miss) > limit * limit) track_status_[i] = 0;
  }
}

Eigen::Matrix3d IntegrateGyro(const std::vector<ImuSample>& samples, TimestampNs start_ns, TimestampNs end_ns,
                              const Eigen::Matrix3d& camera_from_imu) {
  Eigen::Matrix3d earlier_from_later = Eigen::Matrix3d::Identity();
  TimestampNs previous_ns = start_ns;
  for (const ImuSample& sample : samples) {
    if (sample.timestamp_ns <= start_ns) continue;
    const TimestampNs until = std::min(sample.timestamp_ns, end_ns);
    const double dt = NsToSeconds(until - previous_ns);
    const Eigen::Vector3d rotation = camera_from_imu * sample.gyro * dt;
    const double angle = rotation.norm();
    if (angle > 0.0) earlier_from_later *= Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
    previous_ns = until;
    if (until == end_ns) break;
  }
  return earlier_from_later;
}

void DerotateFlow(const CameraIntrinsics& camera, const Eigen::Matrix3d& earlier_from_later,
                  std::vector<FlowVector>* vectors) {
  Eigen::Matrix3d intrinsics;
  intrinsics << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d homography = intrinsics * earlier_from_later.transpose() * intrinsics.inverse();
  for (FlowVector& vector : *vectors) {
    const Eigen::Vector3d moved = homography * Eigen::Vector3d(vector.start.x, vector.start.y, 1.0);
    const cv::Point2f rotational(static_cast<float>(moved.x() / moved.z()) - vector.start.x,
                                 static_cast<float>(moved.y() / moved.z()) - vector.start.y);
    vector.delta -= rotational;
  }
}

}  // namespace patrolmap::flow
