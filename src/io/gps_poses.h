// Internal: camera poses from GPS fixes and an IMU's attitude, for logs with no other pose source (EuRoC
// folders: gps0/ and the attitude columns of imu0/; bags: NavSatFix and Imu.orientation).
//
// The fixes become east, north and up [m] about the point of a 0.1-degree grid of latitude and longitude nearest
// the flight's first fix, at altitude 0 (up is the fix's altitude). Every flight over one site thus shares one
// world frame, which change detection needs, without a survey point to be given; only flights whose first fixes
// lie on either side of a grid line (every 11 km north, 7.5 km east at 48 degrees) get frames apart. East is
// the longitude's arc at the origin's latitude, north the latitude's: over the grid cell's ±5.6 km this scales
// shapes by under 0.1 %, the same in every flight.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "patrolmap/core/types.h"

namespace patrolmap::io {

struct GpsSample {
  TimestampNs timestamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // latitude, longitude [deg], altitude [m]
};

// An IMU's attitude: the rotation taking the IMU's axes into east, north, up.
struct AttitudeSample {
  TimestampNs timestamp_ns = 0;
  Eigen::Quaterniond world_from_imu = Eigen::Quaterniond::Identity();
};

// The origin of the local frame of a flight whose first fix is `first_fix`: latitude and longitude rounded to
// 0.1 degree, altitude 0.
Eigen::Vector3d GpsFrameOrigin(const Eigen::Vector3d& first_fix);

// `fix` (latitude, longitude [deg], altitude [m]) as east, north, up [m] about `origin`.
Eigen::Vector3d EastNorthUp(const Eigen::Vector3d& fix, const Eigen::Vector3d& origin);

// The gaps over which PosesFromGps interpolates.
struct GpsPoseGaps {
  TimestampNs fixes_ns = 2'000'000'000;   // between two fixes: a 1 Hz receiver that missed one
  TimestampNs attitude_ns = 500'000'000;  // between two attitude samples
};

// A camera pose at each of `times` (ascending) that lies between two fixes and two attitude samples no further
// apart than `gaps`: the position interpolated between the fixes, the attitude between its samples, turned by
// the camera's rotation in the IMU's frame. Both tables are in ascending time. The frame's origin comes from
// the first fix.
std::vector<CameraPoseSample> PosesFromGps(const std::vector<GpsSample>& fixes,
                                           const std::vector<AttitudeSample>& attitude,
                                           const Eigen::Quaterniond& imu_from_camera,
                                           const std::vector<TimestampNs>& times, const GpsPoseGaps& gaps = {});

}  // namespace patrolmap::io
