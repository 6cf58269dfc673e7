// Test inputs shared by the change stage's test files.
#ifndef PATROLMAP_TESTS_CHANGE_FIXTURES_H_
#define PATROLMAP_TESTS_CHANGE_FIXTURES_H_

#include <Eigen/Geometry>

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

}  // namespace patrolmap::change::testing_fixtures

#endif  // PATROLMAP_TESTS_CHANGE_FIXTURES_H_
