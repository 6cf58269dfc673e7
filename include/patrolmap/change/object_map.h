// The object map of one patrol (paper 000): each detection is associated with
// an object already in the map or starts a new one. Association: map objects
// whose centroid lies within a gate, then the point-pair test (at least half
// of the nearest-neighbour pairs between the detection's points and the
// object's points closer than a threshold; k-d tree by nanoflann) when the
// detection has depth points, otherwise 2D box overlap of the object's
// projection with a per-category prior on the centroid offset (paper 001).
// A view that shows a new side of an object passes the point-pair test when
// at least half of the object's points it sees lie on its depth surface.
// Every object accumulates label-confidence and label-count pairs; Finish()
// merges objects whose centroids ended up within merge_distance_m (one object
// split by a failed association), gives objects with points the points' extent
// (2nd to 98th percentile) as their box, marks objects with too few detections
// unconfirmed and gives each the label with the highest accumulated
// confidence and that label's mean confidence.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

// Layout of MapObject::descriptor.
constexpr std::size_t kOrientationBins = 8;   // [0, 8): gradient-orientation histogram
constexpr std::size_t kBrightnessRankAt = 8;  // brightness rank

class ObjectMapper {
 public:
  ObjectMapper(const ObjectMapOptions& options, const CameraIntrinsics& camera);

  // Adds the detections of one frame seen from `pose`. `depth_m` (CV_32FC1,
  // may be empty) gives each detection its points; `image` (CV_8UC1 at the
  // camera's size, may be empty) its appearance descriptor. Detections
  // without a 3D centroid take it from the depth; without either they are
  // skipped (counted in skipped()).
  void AddFrame(const std::vector<ObjectObservation>& detections, const CameraPoseSample& pose, const cv::Mat& depth_m,
                const cv::Mat& image);

  // The objects with their final label and confidence; those seen fewer than min_detections times are
  // kept unconfirmed (they are not reported, but a later patrol's sighting there is then no new object).
  std::vector<MapObject> Finish() const;

  int associations() const { return associations_; }  // detections compared with the map
  double association_seconds() const { return association_seconds_; }
  int skipped() const { return skipped_; }
  int forgotten() const { return forgotten_; }  // objects dropped at change.object_map.max_objects

 private:
  struct Candidate;
  struct Measured {
    Eigen::Vector3d centroid;
    std::vector<Eigen::Vector3f> points;             // world frame
    Eigen::Vector2d size = Eigen::Vector2d::Zero();  // width, height [m]
    std::vector<float> descriptor;
  };
  bool Measure(const ObjectObservation& detection, const CameraPoseSample& pose, const cv::Mat& depth_m,
               const cv::Mat& image, Measured* measured) const;
  int Associate(const ObjectObservation& detection, const Measured& measured, const CameraPoseSample& pose,
                const cv::Mat& depth_m) const;
  // Share of the object's points inside `box` and not hidden behind the depth surface that lie on it
  // (within pair_distance_m): the point-pair test against the full depth image, for views showing a new side.
  double SurfaceAgreement(const MapObject& object, const cv::Rect2d& box, const CameraPoseSample& pose,
                          const cv::Mat& depth_m) const;
  void Update(int object, const ObjectObservation& detection, Measured&& measured);
  void ForgetOne();

  ObjectMapOptions options_;
  CameraIntrinsics camera_;
  std::vector<MapObject> objects_;
  std::vector<Eigen::Vector2d> sizes_;       // running mean width, height of each object
  std::array<float, 256> brightness_cdf_{};  // of the current frame's image
  int associations_ = 0;
  double association_seconds_ = 0.0;
  int skipped_ = 0;
  int forgotten_ = 0;
};

// A fixed set of points for nearest-neighbour queries (a k-d tree built once). `points` must outlive it.
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Eigen::Vector3f>& points);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;
  // The share of `query` whose nearest neighbour in the set is closer than `distance`; 0 when either is empty.
  double PairFraction(const std::vector<Eigen::Vector3f>& query, double distance) const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

// Shares of nearest-neighbour pairs closer than `distance`: for each point of
// `query`, its nearest neighbour in `reference` (k-d tree). 0 when either is empty.
double PairFraction(const std::vector<Eigen::Vector3f>& query, const std::vector<Eigen::Vector3f>& reference,
                    double distance);

// Keeps one point per voxel of side `voxel` (the first), in a stable order.
void VoxelFilter(double voxel, std::vector<Eigen::Vector3f>* points);

// Gradient-orientation histogram (8 bins, magnitude-weighted, L1-normalised)
// of `box` in `image`: an appearance descriptor that ignores gain and offset.
std::vector<float> OrientationHistogram(const cv::Mat& image, const cv::Rect& box);

// The image's cumulative grey-level distribution (share of pixels at or below each level).
void CumulativeHistogram(const cv::Mat& image, std::array<float, 256>* cdf);

// Brightness rank of `box`: the share of the image's pixels at or below the median grey level of the
// box's central half. Unchanged by any monotonic change of the lighting (gain, offset, gamma).
float BrightnessRank(const cv::Mat& image, const cv::Rect& box, const std::array<float, 256>& cdf);

// The q-quantile (q in [0, 1]) of the points' coordinate `axis` (0 x, 1 y, 2 z) [m]; 0 with fewer than 10 points.
double PointQuantile(const std::vector<Eigen::Vector3f>& points, int axis, double q);

// Vertical extent of points (5th to 95th percentile of z) [m]; 0 with fewer than 10 points.
double PointHeight(const std::vector<Eigen::Vector3f>& points);

// The image box of an axis-aligned world box seen from `pose`; empty when
// any corner lies behind the camera.
cv::Rect2d ProjectBox(const CameraIntrinsics& camera, const CameraPoseSample& pose, const Eigen::Vector3d& box_min,
                      const Eigen::Vector3d& box_max);

}  // namespace patrolmap::change
