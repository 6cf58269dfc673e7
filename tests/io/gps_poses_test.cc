#include "gps_poses.h"

#include <cmath>

#include <gtest/gtest.h>

namespace patrolmap::io {
namespace {

constexpr double kMetresPerDegree = M_PI / 180.0 * 6378137.0;  // of latitude, and of longitude at the equator

Eigen::Quaterniond Yaw(double degrees) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
}

TEST(GpsPoses, TheOriginIsTheNearestPointOfATenthOfADegreeGridAtAltitudeZero) {
  EXPECT_TRUE(GpsFrameOrigin({47.3572, 8.4370, 480.0}).isApprox(Eigen::Vector3d(47.4, 8.4, 0.0)));
  EXPECT_TRUE(GpsFrameOrigin({-33.86, 151.21, 20.0}).isApprox(Eigen::Vector3d(-33.9, 151.2, 0.0)));
  const Eigen::Vector3d up = EastNorthUp({47.4001, 8.4002, 512.5}, {47.4, 8.4, 0.0});
  EXPECT_NEAR(up.x(), 2e-4 * kMetresPerDegree * std::cos(47.4 * M_PI / 180.0), 1e-6);
  EXPECT_NEAR(up.y(), 1e-4 * kMetresPerDegree, 1e-6);
  EXPECT_DOUBLE_EQ(up.z(), 512.5);
}

// Two flights over one site that take off 300 m apart: the same place gets the same coordinates in both, so their
// grids and objects can be compared.
TEST(GpsPoses, FlightsThatTakeOffApartShareTheFrame) {
  const Eigen::Vector3d place(47.3590, 8.4395, 485.0);
  const std::vector<AttitudeSample> attitude = {{0, Yaw(0)}, {10, Yaw(0)}};
  const std::vector<GpsSample> first = {{0, {47.3572, 8.4370, 480.0}}, {10, place}};
  const std::vector<GpsSample> second = {{0, {47.3545, 8.4360, 478.0}}, {10, place}};
  const auto a = PosesFromGps(first, attitude, Eigen::Quaterniond::Identity(), {10});
  const auto b = PosesFromGps(second, attitude, Eigen::Quaterniond::Identity(), {10});
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_LT((a[0].position - b[0].position).norm(), 1e-9);
}

// Position between the fixes, attitude between its samples, turned by the camera's rotation in the IMU's frame;
// no pose outside either table or across a gap longer than allowed.
TEST(GpsPoses, PosesAreInterpolatedAtTheGivenTimes) {
  constexpr TimestampNs kSecond = 1'000'000'000;
  const std::vector<GpsSample> fixes = {
      {kSecond, {47.0, 8.0, 100.0}}, {2 * kSecond, {47.0, 8.0, 110.0}}, {6 * kSecond, {47.0, 8.0, 150.0}}};
  const std::vector<AttitudeSample> attitude = {{0, Yaw(0)}, {2 * kSecond, Yaw(40)}, {4 * kSecond, Yaw(40)}};
  const Eigen::Quaterniond imu_from_camera(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  GpsPoseGaps gaps;
  gaps.attitude_ns = 2 * kSecond;
  const std::vector<CameraPoseSample> poses =
      PosesFromGps(fixes, attitude, imu_from_camera, {kSecond / 2, kSecond, 3 * kSecond / 2, 4 * kSecond}, gaps);
  // 0.5 s lies before the first fix; 4 s between fixes 4 s apart (more than 2 s).
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].timestamp_ns, kSecond);
  EXPECT_NEAR(poses[0].position.z(), 100.0, 1e-9);
  EXPECT_NEAR(poses[1].position.z(), 105.0, 1e-9);
  EXPECT_NEAR(poses[0].rotation.angularDistance(Yaw(20) * imu_from_camera), 0.0, 1e-9);
  EXPECT_NEAR(poses[1].rotation.angularDistance(Yaw(30) * imu_from_camera), 0.0, 1e-9);
  gaps.attitude_ns = kSecond;  // the attitude's samples lie 2 s apart
  EXPECT_TRUE(PosesFromGps(fixes, attitude, imu_from_camera, {kSecond}, gaps).empty());
  EXPECT_TRUE(PosesFromGps({}, attitude, imu_from_camera, {kSecond}).empty());
}

}  // namespace
}  // namespace patrolmap::io
