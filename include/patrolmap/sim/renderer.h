// Renders grey images of a Scene through a pinhole camera whose optical axis
// is horizontal (the camera may yaw but not pitch or roll). Each image column
// is one vertical plane of rays, so walls are intersected once per column.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/core/types.h"
#include "patrolmap/sim/scene.h"

namespace patrolmap::sim {

// Camera pose: position [m] and yaw of the optical axis, measured from +x
// towards +y [rad]. Image x points to the right of the axis, image y down.
struct CameraPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

// Direction of the camera axes in the world frame.
Eigen::Matrix3d WorldFromCameraRotation(double yaw);

// Projects a world point into the image; false when it is behind the camera.
bool Project(const CameraIntrinsics& camera, const CameraPose& pose, const Eigen::Vector3d& point,
             Eigen::Vector2d* pixel);

class Renderer {
 public:
  Renderer(const Scene* scene, const CameraIntrinsics& camera);

  // Renders into `image` (CV_8UC1, camera.width x camera.height).
  void Render(const CameraPose& pose, cv::Mat* image);

  // Distance along the optical axis of the first surface seen by each column's
  // central ray (the horizon row); +inf for sky. For ground truth and tests.
  void ColumnDepths(const CameraPose& pose, std::vector<double>* depths);

 private:
  struct Hit {
    double depth = 0.0;  // along the optical axis [m]
    double s = 0.0;      // texture coordinate along the wall [m]
    int wall = 0;
  };
  void IntersectColumn(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction);
  void ShadeColumn(int column, const CameraPose& pose, const Eigen::Vector2d& direction, cv::Mat* image) const;
  std::uint8_t ShadeGround(const Eigen::Vector2d& point, double depth) const;
  std::uint8_t ShadeWall(const Hit& hit, double z) const;

  const Scene* scene_;
  CameraIntrinsics camera_;
  std::vector<Hit> hits_;  // of the current column, nearest first
};

// Samples `texture` at (u, v) texels of level 0 with a pixel footprint of
// `footprint` texels (picks the mip level), wrapping when `wrap` is set.
std::uint8_t SampleTexture(const Texture& texture, double u, double v, double footprint, bool wrap);

}  // namespace patrolmap::sim
