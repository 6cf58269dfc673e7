// Ties a patrol's world frame (the pose source's, metres, z up) to the globe, so changes can go on a GIS map:
// a rigid 2D transform from the world's x, y to east, north about the first GPS fix, fitted in least squares
// (Umeyama, without scale) to the kept frames (PatrolRecord::route) that have both a pose and a fix.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

struct GeoReference {
  double origin_latitude = 0.0, origin_longitude = 0.0;    // [deg]: east, north = 0, 0
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();  // east-north from world x-y
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  int fixes = 0;       // frames the fit used
  double rms_m = 0.0;  // their residual [m]

  Eigen::Vector2d EastNorth(const Eigen::Vector3d& world) const;
  Eigen::Vector2d LatitudeLongitude(const Eigen::Vector3d& world) const;  // [deg]
  Eigen::Vector2d EastNorthOf(const Eigen::Vector2d& latitude_longitude) const;
  Eigen::Vector2d WorldOf(const Eigen::Vector2d& latitude_longitude) const;  // the world's x, y
  Eigen::Vector2d NorthInWorld() const;                                      // unit vector in the world's x-y plane
};

// None when fewer than `min_fixes` kept frames have a pose and a fix, or they span less than `min_span_m`.
std::optional<GeoReference> FitGeoReference(const PatrolRecord& record, int min_fixes = 3, double min_span_m = 5.0);

}  // namespace patrolmap::change
