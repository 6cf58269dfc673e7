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

// Illumination and sensor of one flight. The defaults render plain texture
// values (no shading, gain 1, gamma 1, no noise).
struct Lighting {
  double gain = 1.0;             // exposure gain applied to the linear intensity
  double gamma = 1.0;            // output = 255 * (gain * linear / 255)^(1 / gamma)
  double sun_azimuth = 0.0;      // direction towards the sun, from +x towards +y [rad]
  double sun_elevation = 1.57;   // [rad]; walls facing the sun get brighter
  double ambient = 1.0;          // share of light that reaches every surface (1 = no shading)
  double noise_sigma = 0.0;      // Gaussian sensor noise [grey levels]
  std::uint32_t noise_seed = 0;  // with the frame number, seeds each frame's noise
};

// Draws a plausible lighting for flight `flight` of a series from `seed`: gain
// 0.7-1.3, gamma 0.8-1.25, any sun azimuth, elevation 20-60 degrees, ambient
// 0.55, noise sigma 2.
Lighting DrawLighting(std::uint32_t seed, int flight);

// Direction of the camera axes in the world frame.
Eigen::Matrix3d WorldFromCameraRotation(double yaw);

// Projects a world point into the image; false when it is behind the camera.
bool Project(const CameraIntrinsics& camera, const CameraPose& pose, const Eigen::Vector3d& point,
             Eigen::Vector2d* pixel);

class Renderer {
 public:
  Renderer(const Scene* scene, const CameraIntrinsics& camera, const Lighting& lighting = {});

  // Renders into `image` (CV_8UC1, camera.width x camera.height). `frame`
  // seeds the sensor noise, so a frame renders the same every time.
  void Render(const CameraPose& pose, cv::Mat* image, std::uint64_t frame = 0);

  // Depth along the optical axis of every pixel [mm] (CV_16UC1, 0 for sky,
  // 65535 beyond 65.5 m).
  void RenderDepth(const CameraPose& pose, cv::Mat* depth_mm);

  // Distance along the optical axis of the first surface seen by each column's
  // central ray (the horizon row); +inf for sky. For ground truth and tests.
  void ColumnDepths(const CameraPose& pose, std::vector<double>* depths);

 private:
  struct Hit {
    double depth = 0.0;  // along the optical axis [m]
    double s = 0.0;      // texture coordinate along the wall [m]
    int wall = 0;
    float shade = 1.0f;  // illumination of the wall's side that the ray sees
  };
  enum class SurfaceKind { kWall, kRoof, kGround, kSky };
  struct Surface {
    SurfaceKind kind = SurfaceKind::kSky;
    int hit = -1;        // index into hits_ for walls and roofs
    double depth = 0.0;  // along the optical axis [m]; 0 for sky
  };
  Surface SurfaceAt(double height, double slope) const;
  void IntersectColumn(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction);
  void ShadeColumn(int column, const CameraPose& pose, const Eigen::Vector2d& direction, cv::Mat* image) const;
  std::uint8_t ShadeGround(const Eigen::Vector2d& point, double depth) const;
  std::uint8_t ShadeWall(const Hit& hit, double z) const;
  std::uint8_t Expose(double linear) const;  // lighting curve of linear intensity [0, 255+]
  void AddNoise(std::uint64_t frame, cv::Mat* image) const;
  bool HitsRoof(std::size_t index, double height, double slope) const;

  const Scene* scene_;
  CameraIntrinsics camera_;
  Lighting lighting_;
  std::vector<std::uint8_t> exposure_;    // Expose() as a table over linear intensity in quarter steps
  std::vector<Eigen::Vector2d> normals_;  // per wall, unit, to the right of start -> end
  Eigen::Vector2d sun_;                   // horizontal direction towards the sun, scaled by cos(elevation)
  float ground_shade_ = 1.0f;
  cv::Mat noise_;
  std::vector<Hit> hits_;  // of the current column, nearest first
};

// Samples `texture` at (u, v) texels of level 0 with a pixel footprint of
// `footprint` texels (picks the mip level), wrapping when `wrap` is set.
std::uint8_t SampleTexture(const Texture& texture, double u, double v, double footprint, bool wrap);

}  // namespace patrolmap::sim
