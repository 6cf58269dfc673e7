#include <cmath>

#include <gtest/gtest.h>

#include "patrolmap/change/geo_reference.h"

namespace patrolmap::change {
namespace {

constexpr double kEarthRadiusM = 6378137.0, kDegree = M_PI / 180.0;

// Frames around a square 40 m wide whose world frame is turned 30 degrees from east-north and shifted.
PatrolRecord TurnedSquare() {
  const double turn = 30.0 * kDegree, lat0 = 47.0, lon0 = 8.0;
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(turn).toRotationMatrix();
  PatrolRecord record;
  for (int i = 0; i < 40; ++i) {
    const double side = (i % 10) * 4.0;
    const Eigen::Vector2d world[4] = {{side, 0}, {40, side}, {40 - side, 40}, {0, 40 - side}};
    RouteFrame frame;
    frame.timestamp_ns = i;
    frame.pose =
        CameraPoseSample{i, Eigen::Vector3d(world[i / 10].x(), world[i / 10].y(), 2.0), Eigen::Quaterniond::Identity()};
    const Eigen::Vector2d en = rotation * world[i / 10] + Eigen::Vector2d(100.0, -50.0);
    frame.gps = Eigen::Vector2d(lat0 + en.y() / kEarthRadiusM / kDegree,
                                lon0 + en.x() / (kEarthRadiusM * std::cos(lat0 * kDegree)) / kDegree);
    record.route.push_back(frame);
  }
  return record;
}

TEST(GeoReference, RecoversTheTurnAndPlacesEveryFrameOnItsFix) {
  const PatrolRecord record = TurnedSquare();
  const std::optional<GeoReference> geo = FitGeoReference(record);
  ASSERT_TRUE(geo);
  EXPECT_EQ(geo->fixes, 40);
  EXPECT_LT(geo->rms_m, 0.01);
  EXPECT_NEAR(std::atan2(geo->rotation(1, 0), geo->rotation(0, 0)), 30.0 * kDegree, 1e-6);
  for (const RouteFrame& frame : record.route) {
    const Eigen::Vector2d lat_lon = geo->LatitudeLongitude(frame.pose->position);
    EXPECT_NEAR((geo->EastNorthOf(lat_lon) - geo->EastNorthOf(*frame.gps)).norm(), 0.0, 0.01);
    EXPECT_NEAR((geo->WorldOf(*frame.gps) - frame.pose->position.head<2>()).norm(), 0.0, 0.01);
  }
  // North is the world direction turned back by 30 degrees from +y.
  EXPECT_NEAR(geo->NorthInWorld().x(), std::sin(30.0 * kDegree), 1e-9);
  EXPECT_NEAR(geo->NorthInWorld().y(), std::cos(30.0 * kDegree), 1e-9);
}

TEST(GeoReference, NeedsEnoughFixesSpreadFarEnough) {
  PatrolRecord record = TurnedSquare();
  record.route.resize(2);
  EXPECT_FALSE(FitGeoReference(record));  // two fixes
  record = TurnedSquare();
  for (RouteFrame& frame : record.route) frame.pose->position.head<2>() *= 0.01;  // within 0.4 m
  EXPECT_FALSE(FitGeoReference(record));
  record = TurnedSquare();
  for (RouteFrame& frame : record.route) frame.gps.reset();
  EXPECT_FALSE(FitGeoReference(record));
}

}  // namespace
}  // namespace patrolmap::change
