// Test inputs shared by the change stage's test files.
#ifndef PATROLMAP_TESTS_CHANGE_FIXTURES_H_
#define PATROLMAP_TESTS_CHANGE_FIXTURES_H_

#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change::testing_fixtures {

// A 64x48 camera with a 77-degree horizontal field of view.
inline const CameraIntrinsics kCamera{40.0, 40.0, 31.5, 23.5, 64, 48};

inline CameraPoseSample LookingAlongX(const Eigen::Vector3d& position) {
  // Camera z (forward) = world x, camera x (right) = world -y, camera y (down) = world -z.
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);
  r.col(1) = Eigen::Vector3d(0, 0, -1);
  r.col(2) = Eigen::Vector3d(1, 0, 0);
  return {0, position, Eigen::Quaterniond(r)};
}

inline const CameraPoseSample kAtOrigin{0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};

// A wall `wall_m` ahead of a camera standing at the origin; with `box`, a box 4 m ahead in front of it.
inline cv::Mat Depth(float wall_m, bool box) {
  cv::Mat depth(kCamera.height, kCamera.width, CV_32FC1, cv::Scalar(wall_m));
  if (box) depth(cv::Rect(40, 16, 16, 16)).setTo(4.0f);
  return depth;
}

// The grid of 25 views of `depth` from `pose`.
inline EvidenceGrid GridOf(const cv::Mat& depth, const ChangeOptions& options,
                           const CameraPoseSample& pose = kAtOrigin) {
  EvidenceGrid grid(options.grid);
  for (int i = 0; i < 25; ++i) grid.Integrate(depth, kCamera, pose);
  return grid;
}

// A patrol of that camera at `pose`: its views, its detections (a crate 4 m ahead of the origin, seen 10 times, with
// `crate`), and `grid`.
inline PatrolRecord Patrol(const std::string& flight, const EvidenceGrid& grid, bool crate,
                           const CameraPoseSample& pose = kAtOrigin) {
  PatrolRecord record;
  record.flight = flight;
  record.camera = kCamera;
  record.grid = grid.ToData();
  record.depth_source = "images";
  record.has_objects = true;
  for (int i = 0; i < 25; ++i) record.views.push_back({SecondsToNs(0.1 * i), pose.position, pose.rotation});
  if (crate) {
    MapObject object;
    object.label = "crate";
    object.confidence = 0.9;
    object.detections = 10;
    object.centroid = Eigen::Vector3d(0.6, -0.1, 4.2);
    object.box_min = Eigen::Vector3d(0.2, -0.5, 4.0), object.box_max = Eigen::Vector3d(1.0, 0.3, 4.4);
    record.objects = {object};
  }
  return record;
}

}  // namespace patrolmap::change::testing_fixtures

#endif  // PATROLMAP_TESTS_CHANGE_FIXTURES_H_
