#include "patrolmap/change/geo_reference.h"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

namespace patrolmap::change {
namespace {

constexpr double kEarthRadiusM = 6378137.0;  // WGS 84 equatorial radius
constexpr double kDegree = M_PI / 180.0;

}  // namespace

Eigen::Vector2d GeoReference::EastNorth(const Eigen::Vector3d& world) const {
  return rotation * world.head<2>() + translation;
}

// Equirectangular about the origin: exact to centimetres over the few kilometres of a patrol.
Eigen::Vector2d GeoReference::LatitudeLongitude(const Eigen::Vector3d& world) const {
  const Eigen::Vector2d en = EastNorth(world);
  return {origin_latitude + en.y() / kEarthRadiusM / kDegree,
          origin_longitude + en.x() / (kEarthRadiusM * std::cos(origin_latitude * kDegree)) / kDegree};
}

Eigen::Vector2d GeoReference::EastNorthOf(const Eigen::Vector2d& latitude_longitude) const {
  return {(latitude_longitude.y() - origin_longitude) * kDegree * kEarthRadiusM * std::cos(origin_latitude * kDegree),
          (latitude_longitude.x() - origin_latitude) * kDegree * kEarthRadiusM};
}

Eigen::Vector2d GeoReference::WorldOf(const Eigen::Vector2d& latitude_longitude) const {
  return rotation.transpose() * (EastNorthOf(latitude_longitude) - translation);
}

Eigen::Vector2d GeoReference::NorthInWorld() const { return rotation.transpose() * Eigen::Vector2d(0.0, 1.0); }

std::optional<GeoReference> FitGeoReference(const PatrolRecord& record, int min_fixes, double min_span_m) {
  GeoReference geo;
  std::vector<Eigen::Vector2d> world, east_north;
  for (const RouteFrame& frame : record.route) {
    if (!frame.pose || !frame.gps) continue;
    if (world.empty()) geo.origin_latitude = frame.gps->x(), geo.origin_longitude = frame.gps->y();
    world.push_back(frame.pose->position.head<2>());
    east_north.push_back(geo.EastNorthOf(*frame.gps));
  }
  if (static_cast<int>(world.size()) < min_fixes) return std::nullopt;
  Eigen::Matrix2Xd from(2, world.size()), to(2, world.size());
  for (std::size_t i = 0; i < world.size(); ++i) from.col(i) = world[i], to.col(i) = east_north[i];
  const Eigen::Vector2d low = from.rowwise().minCoeff(), high = from.rowwise().maxCoeff();
  if ((high - low).norm() < min_span_m) return std::nullopt;
  const Eigen::Matrix3d transform = Eigen::umeyama(from, to, false);
  geo.rotation = transform.topLeftCorner<2, 2>();
  geo.translation = transform.topRightCorner<2, 1>();
  geo.fixes = static_cast<int>(world.size());
  geo.rms_m = std::sqrt(((geo.rotation * from).colwise() + geo.translation - to).colwise().squaredNorm().mean());
  return geo;
}

}  // namespace patrolmap::change
