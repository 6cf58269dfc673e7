#include "gps_poses.h"

#include <algorithm>
#include <cmath>

namespace patrolmap::io {
namespace {

constexpr double kEarthRadiusM = 6378137.0;  // WGS 84 equatorial radius
constexpr double kRadians = M_PI / 180.0;
constexpr double kGridDeg = 0.1;  // the grid the frame's origin is rounded to

// The sample at or before `t` whose successor lies after it (or at it), no further than `max_gap_ns` away,
// and t's share of the way to the successor; end() when there is none.
template <typename Sample>
typename std::vector<Sample>::const_iterator Around(const std::vector<Sample>& samples, TimestampNs t,
                                                    TimestampNs max_gap_ns, double* share) {
  auto after = std::lower_bound(samples.begin(), samples.end(), t,
                                [](const Sample& sample, TimestampNs time) { return sample.timestamp_ns < time; });
  if (after == samples.end()) return samples.end();
  if (after == samples.begin()) {
    if (after->timestamp_ns != t || samples.size() < 2) return samples.end();
    ++after;  // t is the first sample's time: interpolate at share 0 towards the second
  }
  const auto before = after - 1;
  const TimestampNs gap = after->timestamp_ns - before->timestamp_ns;
  if (gap > max_gap_ns) return samples.end();
  *share = static_cast<double>(t - before->timestamp_ns) / static_cast<double>(gap);
  return before;
}

}  // namespace

Eigen::Vector3d GpsFrameOrigin(const Eigen::Vector3d& first_fix) {
  const auto round = [](double degrees) { return std::round(degrees / kGridDeg) * kGridDeg; };
  return Eigen::Vector3d(round(first_fix.x()), round(first_fix.y()), 0.0);
}

Eigen::Vector3d EastNorthUp(const Eigen::Vector3d& fix, const Eigen::Vector3d& origin) {
  return Eigen::Vector3d((fix.y() - origin.y()) * kRadians * kEarthRadiusM * std::cos(origin.x() * kRadians),
                         (fix.x() - origin.x()) * kRadians * kEarthRadiusM, fix.z() - origin.z());
}

std::vector<CameraPoseSample> PosesFromGps(const std::vector<GpsSample>& fixes,
                                           const std::vector<AttitudeSample>& attitude,
                                           const Eigen::Quaterniond& imu_from_camera,
                                           const std::vector<TimestampNs>& times, const GpsPoseGaps& gaps) {
  std::vector<CameraPoseSample> poses;
  if (fixes.empty()) return poses;
  const Eigen::Vector3d origin = GpsFrameOrigin(fixes.front().position);
  for (const TimestampNs t : times) {
    double fix_share = 0.0, attitude_share = 0.0;
    const auto fix = Around(fixes, t, gaps.fixes_ns, &fix_share);
    const auto turn = Around(attitude, t, gaps.attitude_ns, &attitude_share);
    if (fix == fixes.end() || turn == attitude.end()) continue;
    CameraPoseSample pose;
    pose.timestamp_ns = t;
    const Eigen::Vector3d position = (1.0 - fix_share) * fix->position + fix_share * (fix + 1)->position;
    pose.position = EastNorthUp(position, origin);
    const Eigen::Quaterniond world_from_imu = turn->world_from_imu.slerp(attitude_share, (turn + 1)->world_from_imu);
    pose.rotation = (world_from_imu * imu_from_camera).normalized();
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace patrolmap::io
