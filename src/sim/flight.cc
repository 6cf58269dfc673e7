#include "patrolmap/sim/flight.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "patrolmap/core/files.h"

namespace patrolmap::sim {
namespace {

constexpr double kGravity = 9.81;
// A view-axis depth jump is a key location when the inverse depth (what optical
// flow measures) changes by at least this much [1/m]: 6 m -> 48 m is one,
// 22 m -> 35 m behind a gap is not.
constexpr double kMinInverseDepthChange = 0.05;

Eigen::Matrix3d WorldFromBody(double heading) {
  return Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

std::string MatrixYaml(const Eigen::Matrix3d& rotation) {
  std::ostringstream out;
  out.precision(12);
  out << "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      const double value = row < 3 && col < 3 ? rotation(row, col) : (row == col ? 1.0 : 0.0);
      out << value << (row == 3 && col == 3 ? "]\n" : ", ");
    }
  }
  return out.str();
}

std::string CameraYaml(const SimulatedFlight& flight) {
  const CameraIntrinsics& camera = flight.camera;
  std::ostringstream out;
  out.precision(12);
  out << "sensor_type: camera\ncomment: patrolmap simulated camera\n" << MatrixYaml(BodyFromCamera(flight.mount_angle))
      << "rate_hz: " << flight.frame_rate_hz << "\nresolution: [" << camera.width << ", " << camera.height
      << "]\ncamera_model: pinhole\nintrinsics: [" << camera.fx << ", " << camera.fy << ", " << camera.cx << ", "
      << camera.cy << "]\ndistortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";
  return out.str();
}

std::string MetaYaml(const SimulatedFlight& flight) {
  std::ostringstream out;
  out.precision(12);
  out << "flight_id: " << flight.flight_id << "\nsimulated: true\nframe_rate_hz: " << flight.frame_rate_hz
      << "\nmount_angle_deg: " << flight.mount_angle * 180.0 / M_PI << "\ncamera:\n  fx: " << flight.camera.fx
      << "\n  fy: " << flight.camera.fy << "\n  cx: " << flight.camera.cx << "\n  cy: " << flight.camera.cy
      << "\n  width: " << flight.camera.width << "\n  height: " << flight.camera.height << "\n";
  return out.str();
}

std::string ImuTable(const SimulatedFlight& flight) {
  std::ostringstream out;
  out.precision(9);
  out << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
         "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (const ImuSample& sample : ImuSamples(flight)) {
    out << sample.timestamp_ns << "," << sample.gyro.x() << "," << sample.gyro.y() << "," << sample.gyro.z() << ","
        << sample.accel.x() << "," << sample.accel.y() << "," << sample.accel.z() << "\n";
  }
  return out.str();
}

std::string StateTable(const SimulatedFlight& flight) {
  std::ostringstream out;
  out.precision(9);
  out << "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z [],"
         "v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1]\n";
  for (int frame = 0; frame < FrameCount(flight); ++frame) {
    const PlatformState state = flight.trajectory(frame / flight.frame_rate_hz);
    const Eigen::Quaterniond q(WorldFromBody(state.heading));
    out << FrameTimestamp(flight, frame) << "," << state.position.x() << "," << state.position.y() << ","
        << state.position.z() << "," << q.w() << "," << q.x() << "," << q.y() << "," << q.z() << ","
        << state.velocity.x() << "," << state.velocity.y() << "," << state.velocity.z() << "\n";
  }
  return out.str();
}

std::string TruthTable(const std::vector<TruthKeyLocation>& truth) {
  std::ostringstream out;
  out.precision(9);
  out << "#timestamp [ns],frame_index,kind,edge_x [m],edge_y [m],depth_before [m],depth_after [m]\n";
  for (const TruthKeyLocation& event : truth) {
    out << event.timestamp_ns << "," << event.frame_index << "," << (event.opening ? "opening" : "closing") << ","
        << event.edge.x() << "," << event.edge.y() << "," << event.depth_before << "," << event.depth_after << "\n";
  }
  return out.str();
}

Status WriteFrames(const SimulatedFlight& flight, const std::string& folder, const ProgressCallback& progress) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/cam0/data"));
  Renderer renderer(&flight.scene, flight.camera, flight.lighting);
  std::ostringstream table;
  table << "#timestamp [ns],filename\n";
  cv::Mat image;
  const int frames = FrameCount(flight);
  for (int frame = 0; frame < frames; ++frame) {
    const TimestampNs timestamp = FrameTimestamp(flight, frame);
    renderer.Render(CameraPoseAt(flight, flight.trajectory(frame / flight.frame_rate_hz)), &image, frame);
    const std::string name = std::to_string(timestamp) + ".png";
    if (!cv::imwrite(folder + "/cam0/data/" + name, image)) {
      return Status::IoError(folder + "/cam0/data/" + name + ": cannot write image");
    }
    table << timestamp << "," << name << "\n";
    if (progress) progress(frame + 1, frames);
  }
  return WriteFileAtomically(folder + "/cam0/data.csv", table.str());
}

// Depth along the optical axis of the first wall at least as tall as the camera.
double AxisDepth(Renderer* renderer, const CameraPose& pose, int centre_column, std::vector<double>* depths) {
  renderer->ColumnDepths(pose, depths);
  return (*depths)[centre_column];
}

}  // namespace

Eigen::Matrix3d BodyFromCamera(double mount_angle) {
  Eigen::Matrix3d rotation;
  rotation.col(0) = Eigen::Vector3d(std::sin(mount_angle), -std::cos(mount_angle), 0.0);
  rotation.col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);
  rotation.col(2) = Eigen::Vector3d(std::cos(mount_angle), std::sin(mount_angle), 0.0);
  return rotation;
}

std::vector<ImuSample> ImuSamples(const SimulatedFlight& flight) {
  const int count = static_cast<int>(flight.duration_s * flight.imu_rate_hz) + 1;
  std::vector<ImuSample> samples(count);
  for (int i = 0; i < count; ++i) {
    const double t = i / flight.imu_rate_hz;
    const PlatformState state = flight.trajectory(t);
    samples[i].timestamp_ns = SecondsToNs(t);
    samples[i].gyro = Eigen::Vector3d(0.0, 0.0, state.yaw_rate);  // level flight: yaw only
    samples[i].accel =
        WorldFromBody(state.heading).transpose() * (state.acceleration + Eigen::Vector3d(0, 0, kGravity));
  }
  return samples;
}

CameraPose CameraPoseAt(const SimulatedFlight& flight, const PlatformState& state) {
  return {state.position, state.heading + flight.mount_angle};
}

int FrameCount(const SimulatedFlight& flight) {
  return static_cast<int>(std::floor(flight.duration_s * flight.frame_rate_hz)) + 1;
}

TimestampNs FrameTimestamp(const SimulatedFlight& flight, int frame) {
  return SecondsToNs(frame / flight.frame_rate_hz);
}

std::vector<TruthKeyLocation> KeyLocationTruth(const SimulatedFlight& flight) {
  std::vector<TruthKeyLocation> truth;
  Renderer renderer(&flight.scene, flight.camera);
  std::vector<double> depths;
  const int centre = static_cast<int>(std::lround(flight.camera.cx));
  CameraPose previous = CameraPoseAt(flight, flight.trajectory(0.0));
  double previous_depth = AxisDepth(&renderer, previous, centre, &depths);
  for (int frame = 1; frame < FrameCount(flight); ++frame) {
    const CameraPose pose = CameraPoseAt(flight, flight.trajectory(frame / flight.frame_rate_hz));
    const double depth = AxisDepth(&renderer, pose, centre, &depths);
    if (std::abs(1.0 / depth - 1.0 / previous_depth) >= kMinInverseDepthChange) {
      TruthKeyLocation event;
      event.timestamp_ns = FrameTimestamp(flight, frame);
      event.frame_index = frame;
      event.opening = depth > previous_depth;
      event.depth_before = previous_depth;
      event.depth_after = depth;
      const Eigen::Vector3d axis = WorldFromCameraRotation(pose.yaw).col(2);
      event.edge = (pose.position + std::min(depth, previous_depth) * axis).head<2>();
      truth.push_back(event);
    }
    previous_depth = depth;
  }
  return truth;
}

Status WriteEurocLog(const SimulatedFlight& flight, const std::string& folder, const ProgressCallback& progress) {
  if (!flight.trajectory || flight.duration_s <= 0.0) return Status::InvalidArgument("flight has no trajectory");
  for (const char* sub : {"/imu0", "/state_groundtruth_estimate0", "/groundtruth"}) {
    PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + sub));
  }
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/meta.yaml", MetaYaml(flight)));
  PATROLMAP_RETURN_IF_ERROR(WriteFrames(flight, folder, progress));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/cam0/sensor.yaml", CameraYaml(flight)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(
      folder + "/imu0/sensor.yaml", "sensor_type: imu\n" + MatrixYaml(Eigen::Matrix3d::Identity()) +
                                        "rate_hz: " + std::to_string(flight.imu_rate_hz) + "\n"));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/imu0/data.csv", ImuTable(flight)));
  PATROLMAP_RETURN_IF_ERROR(
      WriteFileAtomically(folder + "/state_groundtruth_estimate0/data.csv", StateTable(flight)));
  return WriteFileAtomically(folder + "/groundtruth/key_locations.csv", TruthTable(KeyLocationTruth(flight)));
}

}  // namespace patrolmap::sim
