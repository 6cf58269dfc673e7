#include "patrolmap/sim/flight.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/core/files.h"

namespace patrolmap::sim {
namespace {

constexpr double kGravity = 9.81;
// The view axis passes a key location when the inverse depth along it (what
// optical flow measures) has changed by at least this much since the last one
// [1/m]: 6 m -> 48 m is one, 22 m -> 35 m behind a gap is not; a wall seen
// obliquely counts once its gradual change adds up.
constexpr double kMinInverseDepthChange = 0.05;
// While the platform turns faster than this, the axis sweeps over the scene by
// rotation, not by passing buildings: no key location during the turn, one
// after it when the view before and after differs enough [rad/s] (corner arcs
// turn at 0.43 rad/s).
constexpr double kTurnRate = 0.25;

Eigen::Matrix3d WorldFromBody(double heading) {
  return Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

std::string MatrixYaml(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation = Eigen::Vector3d::Zero()) {
  std::ostringstream out;
  out.precision(12);
  out << "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      double value = row < 3 && col < 3 ? rotation(row, col) : (row == col ? 1.0 : 0.0);
      if (row < 3 && col == 3) value = translation[row];
      out << value << (row == 3 && col == 3 ? "]\n" : ", ");
    }
  }
  return out.str();
}

// cam0 (baseline 0) or, `baseline_m` to its right, cam1 of the stereo pair.
std::string CameraYaml(const SimulatedFlight& flight, double rate_hz, double baseline_m = 0.0) {
  const CameraIntrinsics& camera = flight.camera;
  const Eigen::Matrix3d body_from_camera = BodyFromCamera(flight.mount_angle);
  std::ostringstream out;
  out.precision(12);
  out << "sensor_type: camera\ncomment: patrolmap simulated camera\n"
      << MatrixYaml(body_from_camera, body_from_camera * Eigen::Vector3d(baseline_m, 0.0, 0.0))
      << "rate_hz: " << rate_hz << "\nresolution: [" << camera.width << ", " << camera.height
      << "]\ncamera_model: pinhole\nintrinsics: [" << camera.fx << ", " << camera.fy << ", " << camera.cx << ", "
      << camera.cy << "]\ndistortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";
  return out.str();
}

std::string MetaYaml(const SimulatedFlight& flight, double rate_hz) {
  std::ostringstream out;
  out.precision(12);
  out << "flight_id: " << flight.flight_id << "\nsimulated: true\nframe_rate_hz: " << rate_hz
      << "\nmount_angle_deg: " << flight.mount_angle * 180.0 / M_PI << "\ncamera:\n  fx: " << flight.camera.fx
      << "\n  fy: " << flight.camera.fy << "\n  cx: " << flight.camera.cx << "\n  cy: " << flight.camera.cy
      << "\n  width: " << flight.camera.width << "\n  height: " << flight.camera.height << "\n";
  return out.str();
}

// With GPS the IMU also reports its attitude (an AHRS): the body's rotation into east, north, up, off by a rotation
// drawn once per flight (each axis's angle normal with attitude_noise_deg).
std::string ImuTable(const SimulatedFlight& flight, const LogOptions& options) {
  std::ostringstream out;
  out.precision(9);
  out << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
         "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"
      << (options.gps ? ",q_WS_w [],q_WS_x [],q_WS_y [],q_WS_z []" : "") << "\n";
  cv::RNG rng(static_cast<std::uint64_t>(flight.lighting.noise_seed) * 89u + 7u);
  const double sigma = options.attitude_noise_deg * M_PI / 180.0;
  const Eigen::Vector3d error_angles(rng.gaussian(sigma), rng.gaussian(sigma), rng.gaussian(sigma));
  const Eigen::Matrix3d error = Eigen::AngleAxisd(error_angles.norm(), error_angles.normalized()).toRotationMatrix();
  for (const ImuSample& sample : ImuSamples(flight)) {
    out << sample.timestamp_ns << "," << sample.gyro.x() << "," << sample.gyro.y() << "," << sample.gyro.z() << ","
        << sample.accel.x() << "," << sample.accel.y() << "," << sample.accel.z();
    if (options.gps) {
      const PlatformState state = flight.trajectory(static_cast<double>(sample.timestamp_ns) * 1e-9);
      const Eigen::Quaterniond q(error * WorldFromBody(state.heading));
      out << "," << q.w() << "," << q.x() << "," << q.y() << "," << q.z();
    }
    out << "\n";
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

std::string PlacesTable(const SimulatedFlight& flight) {
  std::ostringstream out;
  out.precision(9);
  out << "#timestamp [ns],frame_index,x [m],y [m],z [m],camera_yaw [rad]\n";
  for (int frame = 0; frame < FrameCount(flight); ++frame) {
    const CameraPose pose = CameraPoseAt(flight, flight.trajectory(frame / flight.frame_rate_hz));
    out << FrameTimestamp(flight, frame) << "," << frame << "," << pose.position.x() << "," << pose.position.y() << ","
        << pose.position.z() << "," << std::remainder(pose.yaw, 2 * M_PI) << "\n";
  }
  return out.str();
}

std::string ObjectsTable(const std::vector<WorldObject>& objects) {
  std::ostringstream out;
  out.precision(9);
  out << "#id,label,x [m],y [m],yaw [rad],length [m],width [m],height [m]\n";
  for (const WorldObject& o : objects) {
    out << o.id << "," << ToString(o.label) << "," << o.centre.x() << "," << o.centre.y() << "," << o.yaw << ","
        << o.length << "," << o.width << "," << o.height << "\n";
  }
  return out.str();
}

std::string ChangesTable(const std::vector<ObjectChange>& changes) {
  std::ostringstream out;
  out.precision(9);
  out << "#id,label,state,x_before [m],y_before [m],x_after [m],y_after [m]\n";
  for (const ObjectChange& c : changes) {
    out << c.id << "," << ToString(c.label) << "," << ToString(c.state) << "," << c.before.x() << "," << c.before.y()
        << "," << c.after.x() << "," << c.after.y() << "\n";
  }
  return out.str();
}

std::string GpsTable(const SimulatedFlight& flight, const LogOptions& options) {
  constexpr double kEarthRadius = 6378137.0, kRateHz = 10.0;
  const double kSigma = options.gps_noise_m;
  cv::RNG rng(static_cast<std::uint64_t>(flight.lighting.noise_seed) * 97u + 1u);
  std::ostringstream out;
  out.precision(10);
  out << "#timestamp [ns],latitude [deg],longitude [deg],altitude [m]\n";
  const double lat0 = options.gps_origin_latitude * M_PI / 180.0;
  cv::RNG bias_rng(static_cast<std::uint64_t>(flight.lighting.noise_seed) * 101u + 3u);
  const Eigen::Vector3d bias(bias_rng.gaussian(options.gps_bias_m), bias_rng.gaussian(options.gps_bias_m),
                             bias_rng.gaussian(options.gps_bias_m));
  for (double t = 0.0; t <= flight.duration_s; t += 1.0 / kRateHz) {
    const Eigen::Vector3d p = flight.trajectory(t).position + bias;
    const double north = p.y() + rng.gaussian(kSigma), east = p.x() + rng.gaussian(kSigma);
    out << SecondsToNs(t) << "," << options.gps_origin_latitude + north / kEarthRadius * 180.0 / M_PI << ","
        << options.gps_origin_longitude + east / (kEarthRadius * std::cos(lat0)) * 180.0 / M_PI << ","
        << options.gps_origin_altitude_m + p.z() + rng.gaussian(2 * kSigma) << "\n";
  }
  return out.str();
}

// Accumulates the per-frame tables while frames are rendered.
struct FrameTables {
  std::ostringstream images, depth, detections, detection_truth;
  FrameTables() {
    images << "#timestamp [ns],filename\n";
    depth << "#timestamp [ns],filename\n";
    detections << "#timestamp [ns],label,confidence,x_min [px],y_min [px],x_max [px],y_max [px],"
                  "x_c [m],y_c [m],z_c [m]\n";
    detection_truth << "#timestamp [ns],detection,object_id\n";
    detections.precision(6);
  }
};

void AppendDetections(TimestampNs timestamp, const std::vector<Detection>& found, FrameTables* tables) {
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Detection& d = found[i];
    tables->detections << timestamp << "," << ToString(d.label) << "," << d.confidence << "," << d.box.x << ","
                       << d.box.y << "," << d.box.br().x << "," << d.box.br().y << "," << d.centroid.x() << ","
                       << d.centroid.y() << "," << d.centroid.z() << "\n";
    tables->detection_truth << timestamp << "," << i << "," << d.truth_id << "\n";
  }
}

Status WriteImage(const std::string& path, const cv::Mat& image) {
  return cv::imwrite(path, image) ? Status::Ok() : Status::IoError(path + ": cannot write image");
}

// The pose of a camera `baseline_m` to the right of the flight's camera (0: that camera) at `t`.
CameraPose ShiftedPose(const SimulatedFlight& flight, double t, double baseline_m) {
  CameraPose pose = CameraPoseAt(flight, flight.trajectory(t));
  pose.position += baseline_m * WorldFromCameraRotation(pose.yaw).col(0);
  return pose;
}

// Renders frame `frame` of the camera `baseline_m` to the right of the flight's (0: the flight's camera; its
// sensor noise is drawn apart); with an exposure time, the mean of kBlurSamples renders spread over it.
void RenderFrame(const SimulatedFlight& flight, double exposure_s, int frame, double baseline_m, Renderer* renderer,
                 cv::Mat* image, cv::Mat* sum, cv::Mat* sample) {
  constexpr int kBlurSamples = 5;
  constexpr int kRightNoiseOffset = 1 << 24;  // sensor noise of the right camera differs from the left one's
  const double t = frame / flight.frame_rate_hz;
  const int noise = baseline_m > 0.0 ? frame + kRightNoiseOffset : frame;
  if (exposure_s <= 0.0) {
    renderer->Render(ShiftedPose(flight, t, baseline_m), image, noise);
    return;
  }
  sum->create(flight.camera.height, flight.camera.width, CV_32FC1);
  sum->setTo(0.0);
  for (int i = 0; i < kBlurSamples; ++i) {
    const double offset = exposure_s * ((i + 0.5) / kBlurSamples - 0.5);
    const double when = std::clamp(t + offset, 0.0, flight.duration_s);
    renderer->Render(ShiftedPose(flight, when, baseline_m), sample, noise);
    cv::accumulate(*sample, *sum);
  }
  sum->convertTo(*image, CV_8UC1, 1.0 / kBlurSamples);
}

Status WriteFrames(const SimulatedFlight& flight, const std::string& folder, const LogOptions& options,
                   const ProgressCallback& progress, FrameTables* tables) {
  Renderer renderer(&flight.scene, flight.camera, flight.lighting);
  const int detector_step = std::max(1, static_cast<int>(std::lround(flight.frame_rate_hz / options.detector.rate_hz)));
  cv::Mat image, depth, sum, sample;
  const int frames = FrameCount(flight);
  int next_detection = 0;  // the detector reports on the first written frame this many frames after its last
  for (int frame = 0; frame < frames; frame += options.frame_step) {
    const TimestampNs timestamp = FrameTimestamp(flight, frame);
    const CameraPose pose = CameraPoseAt(flight, flight.trajectory(frame / flight.frame_rate_hz));
    const std::string name = std::to_string(timestamp) + ".png";
    RenderFrame(flight, options.exposure_s, frame, 0.0, &renderer, &image, &sum, &sample);
    PATROLMAP_RETURN_IF_ERROR(WriteImage(folder + "/cam0/data/" + name, image));
    tables->images << timestamp << "," << name << "\n";
    if (options.stereo_baseline_m > 0.0) {
      RenderFrame(flight, options.exposure_s, frame, options.stereo_baseline_m, &renderer, &image, &sum, &sample);
      PATROLMAP_RETURN_IF_ERROR(WriteImage(folder + "/cam1/data/" + name, image));
    }
    if (options.depth) {
      renderer.RenderDepth(pose, &depth);
      PATROLMAP_RETURN_IF_ERROR(WriteImage(folder + "/depth0/data/" + name, depth));
      tables->depth << timestamp << "," << name << "\n";
    }
    if (options.detections && frame >= next_detection) {
      next_detection = frame + detector_step;
      AppendDetections(
          timestamp, DetectObjects(flight.objects, flight.scene, flight.camera, pose, options.detector, frame), tables);
    }
    if (progress) progress(frame + 1, frames);
  }
  return Status::Ok();
}

Status WriteOptionalTables(const SimulatedFlight& flight, const std::string& folder, const LogOptions& options,
                           const FrameTables& tables) {
  if (options.depth) PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/depth0/data.csv", tables.depth.str()));
  if (options.detections) {
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/objects0/data.csv", tables.detections.str()));
    PATROLMAP_RETURN_IF_ERROR(
        WriteFileAtomically(folder + "/groundtruth/detections.csv", tables.detection_truth.str()));
  }
  if (options.gps) PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/gps0/data.csv", GpsTable(flight, options)));
  return Status::Ok();
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

int WrittenFrameCount(const SimulatedFlight& flight, const LogOptions& options) {
  return (FrameCount(flight) + options.frame_step - 1) / options.frame_step;
}

double WrittenFrameRate(const SimulatedFlight& flight, const LogOptions& options) {
  return flight.frame_rate_hz / options.frame_step;
}

TimestampNs FrameTimestamp(const SimulatedFlight& flight, int frame) {
  return SecondsToNs(frame / flight.frame_rate_hz);
}

std::vector<TruthKeyLocation> KeyLocationTruth(const SimulatedFlight& flight) {
  std::vector<TruthKeyLocation> truth;
  Renderer renderer(&flight.scene, flight.camera);
  std::vector<double> depths;
  const int centre = static_cast<int>(std::lround(flight.camera.cx));
  // Inverse depth along the axis at the last event (or the start); sky is 0.
  double reference = 1.0 / AxisDepth(&renderer, CameraPoseAt(flight, flight.trajectory(0.0)), centre, &depths);
  for (int frame = 1; frame < FrameCount(flight); ++frame) {
    const PlatformState state = flight.trajectory(frame / flight.frame_rate_hz);
    const CameraPose pose = CameraPoseAt(flight, state);
    const double depth = AxisDepth(&renderer, pose, centre, &depths);
    const double inverse = 1.0 / depth;
    // While turning the axis sweeps by rotation: no event, and the reference stays at its value from
    // before the turn, so the first straight frame compares the views before and after the turn.
    if (std::abs(state.yaw_rate) > kTurnRate) continue;
    if (std::abs(inverse - reference) < kMinInverseDepthChange) continue;
    TruthKeyLocation event;
    event.timestamp_ns = FrameTimestamp(flight, frame);
    event.frame_index = frame;
    event.opening = inverse < reference;
    event.depth_before = 1.0 / reference;
    event.depth_after = depth;
    const Eigen::Vector3d axis = WorldFromCameraRotation(pose.yaw).col(2);
    event.edge = (pose.position + std::min(depth, event.depth_before) * axis).head<2>();
    truth.push_back(event);
    reference = inverse;
  }
  return truth;
}

Status WriteEurocLog(const SimulatedFlight& flight, const std::string& folder, const LogOptions& options,
                     const ProgressCallback& progress) {
  if (!flight.trajectory || flight.duration_s <= 0.0) return Status::InvalidArgument("flight has no trajectory");
  if (options.frame_step < 1) return Status::InvalidArgument("frame step must be at least 1");
  if (options.truth_only) {
    PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/groundtruth"));
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/groundtruth/objects.csv", ObjectsTable(flight.objects)));
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/groundtruth/changes.csv", ChangesTable(flight.changes)));
    return WriteFileAtomically(folder + "/groundtruth/key_locations.csv", TruthTable(KeyLocationTruth(flight)));
  }
  for (const char* sub : {"/cam0/data", "/imu0", "/state_groundtruth_estimate0", "/groundtruth"}) {
    PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + sub));
  }
  if (options.depth) PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/depth0/data"));
  if (options.stereo_baseline_m > 0.0) PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/cam1/data"));
  if (options.detections) PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/objects0"));
  if (options.gps) PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/gps0"));
  PATROLMAP_RETURN_IF_ERROR(
      WriteFileAtomically(folder + "/meta.yaml", MetaYaml(flight, WrittenFrameRate(flight, options))));
  FrameTables tables;
  PATROLMAP_RETURN_IF_ERROR(WriteFrames(flight, folder, options, progress, &tables));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/cam0/data.csv", tables.images.str()));
  PATROLMAP_RETURN_IF_ERROR(
      WriteFileAtomically(folder + "/cam0/sensor.yaml", CameraYaml(flight, WrittenFrameRate(flight, options))));
  if (options.stereo_baseline_m > 0.0) {
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/cam1/data.csv", tables.images.str()));
    PATROLMAP_RETURN_IF_ERROR(
        WriteFileAtomically(folder + "/cam1/sensor.yaml",
                            CameraYaml(flight, WrittenFrameRate(flight, options), options.stereo_baseline_m)));
  }
  PATROLMAP_RETURN_IF_ERROR(
      WriteFileAtomically(folder + "/imu0/sensor.yaml", "sensor_type: imu\n" + MatrixYaml(Eigen::Matrix3d::Identity()) +
                                                            "rate_hz: " + std::to_string(flight.imu_rate_hz) + "\n"));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/imu0/data.csv", ImuTable(flight, options)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/state_groundtruth_estimate0/data.csv", StateTable(flight)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/groundtruth/places.csv", PlacesTable(flight)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/groundtruth/objects.csv", ObjectsTable(flight.objects)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/groundtruth/changes.csv", ChangesTable(flight.changes)));
  PATROLMAP_RETURN_IF_ERROR(WriteOptionalTables(flight, folder, options, tables));
  return WriteFileAtomically(folder + "/groundtruth/key_locations.csv", TruthTable(KeyLocationTruth(flight)));
}

}  // namespace patrolmap::sim
