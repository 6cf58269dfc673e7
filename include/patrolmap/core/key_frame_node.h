// A key frame as a node: the one type place recognition describes and the topological map keeps, from the
// recognizer's result to map.pmap and back, so no copy has to be kept in step with another by id.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/core/types.h"

namespace patrolmap {

using WordId = std::uint32_t;

// A sparse, L1-normalised TF-IDF vector (vocab/bow.h): words sorted ascending, weights > 0 summing to 1.
struct BowVector {
  std::vector<WordId> words;
  std::vector<float> weights;
  bool empty() const { return words.empty(); }
};

struct KeyFrameNode {
  std::string flight;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  // Feature positions in the image the features were found in [pixels], and their descriptors (vocab/descriptors.h:
  // float, 8-bit or packed 4-bit rows), kept so a later flight can be matched without the original log.
  std::vector<cv::Point2f> points;
  cv::Mat descriptors;
  BowVector bow;
  cv::Mat thumbnail;                                 // CV_8UC1 key frame, small (for pictures and exports)
  std::optional<Eigen::Vector2d> gps;                // latitude, longitude [deg], when the log has them
  double heading = 0.0;                              // integrated gyro yaw at the node [rad] (0 without an IMU)
  Eigen::Vector2d layout = Eigen::Vector2d::Zero();  // 2D position for pictures (scaleless)
};

}  // namespace patrolmap
