// EuRoC/ASL flight-log reader (DESIGN.md "Flight logs").
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>

#include <spdlog/spdlog.h>
#include <Eigen/Geometry>

#include "euroc_tables.h"
#include "image_list_source.h"
#include "image_times.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/core/files.h"
#include "patrolmap/io/camera_file.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/io/yaml_file.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

// CAMERA/data.csv: timestamp, file name under CAMERA/data/.
Status ReadCameraTable(const std::string& log, const std::string& camera, std::vector<ImageEntry>* entries) {
  const std::string path = log + "/" + camera + "/data.csv";
  const auto parse = [&](const CsvReader& csv, const std::vector<std::string_view>& fields, ImageEntry* entry) {
    std::string name;
    PATROLMAP_RETURN_IF_ERROR(ParseFileName(csv, fields[1], &name));
    entry->path = log + "/" + camera + "/data/" + name;
    return Status::Ok();
  };
  PATROLMAP_RETURN_IF_ERROR(ReadTimedTable(path, 2, parse, entries));
  if (entries->empty()) return Status::DataLoss(path + ": no frames listed");
  return Status::Ok();
}

// imu0/data.csv: timestamp, gyro xyz [rad/s], accelerometer xyz [m/s^2], and optionally the IMU's attitude as a
// quaternion w, x, y, z (its axes into east, north, up: what an AHRS reports) on the rows that have it.
Status ReadImuTable(const std::string& path, std::vector<ImuSample>* samples, std::vector<AttitudeSample>* attitude) {
  const auto parse = [attitude](const CsvReader& csv, const std::vector<std::string_view>& fields, ImuSample* sample) {
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 1, "w_RS_S [rad s^-1]", &sample->gyro));
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 4, "a_RS_S [m s^-2]", &sample->accel));
    if (fields.size() == 7) return Status::Ok();
    if (fields.size() < 11) {  // a row cut short, or an attitude missing columns: not taken for none
      return csv.Error("expected 7 columns, or 11 with the attitude, found " + std::to_string(fields.size()));
    }
    AttitudeSample turn{sample->timestamp_ns, Eigen::Quaterniond::Identity()};
    PATROLMAP_RETURN_IF_ERROR(ParseUnitQuaternion(csv, fields, 7, "q_WS (attitude)", &turn.world_from_imu));
    attitude->push_back(turn);
    return Status::Ok();
  };
  return ReadTimedTable(path, 7, parse, samples);
}

// EuRoC ground-truth state: timestamp, position (3), quaternion (4), velocity (3), ...
Status ReadSpeedTable(const std::string& path, std::vector<SpeedSample>* samples) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, SpeedSample* sample) {
    Eigen::Vector3d velocity;
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 8, "v_RS_R [m s^-1]", &velocity));
    sample->speed_mps = velocity.norm();
    return Status::Ok();
  };
  return ReadTimedTable(path, 11, parse, samples);
}

Status ReadNumbers(const std::string& path, const YAML::Node& node, const char* key, std::size_t count,
                   std::vector<double>* values) {
  try {
    *values = node.as<std::vector<double>>();
  } catch (const YAML::Exception&) {
    return Status::DataLoss(path + ": '" + key + "' must be a list of numbers");
  }
  if (values->size() != count) {
    return Status::DataLoss(path + ": '" + key + "' must have " + std::to_string(count) + " numbers, has " +
                            std::to_string(values->size()));
  }
  return Status::Ok();
}

// Reads the optional frame rate `key` of a YAML file into `rate_hz` (unchanged when absent): a finite
// number above 0, or the file is refused naming the key.
// The highest frame rate a log may declare (input.frame_rate_hz's bound too) [Hz].
constexpr double kMaxFrameRateHz = 10000.0;

Status ReadRate(const std::string& path, const YAML::Node& root, const char* key, double* rate_hz) {
  if (!root[key]) return Status::Ok();
  double value = 0.0;
  try {
    value = root[key].as<double>();
  } catch (const YAML::Exception&) {
    value = 0.0;
  }
  if (!std::isfinite(value) || value <= 0.0 || value > kMaxFrameRateHz) {
    return Status::DataLoss(path + ": '" + key + "' must be a frame rate above 0 and at most " +
                            std::to_string(static_cast<int>(kMaxFrameRateHz)) + " [Hz]");
  }
  *rate_hz = value;
  return Status::Ok();
}

// Reads T_BS (body from sensor) of a sensor.yaml: its rotation, and its translation when `translation` is
// not null; identity when absent.
Status ReadBodyFromSensor(const std::string& path, const YAML::Node& root, Eigen::Matrix3d* rotation,
                          Eigen::Vector3d* translation = nullptr) {
  rotation->setIdentity();
  if (translation != nullptr) translation->setZero();
  if (!root["T_BS"]) return Status::Ok();
  if (!root["T_BS"].IsMap()) return Status::DataLoss(path + ": 'T_BS' must be a map with 'data'");
  std::vector<double> data;
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["T_BS"]["data"], "T_BS.data", 16, &data));
  if (!std::all_of(data.begin(), data.end(), [](double v) { return std::isfinite(v); })) {
    return Status::DataLoss(path + ": 'T_BS.data' holds a value that is not a finite number");
  }
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) (*rotation)(row, col) = data[row * 4 + col];
    if (translation != nullptr) (*translation)[row] = data[row * 4 + 3];
  }
  // A rotation's rows are orthonormal and its determinant 1; EuRoC's calibrations hold 1e-6 of that.
  constexpr double kRotationTolerance = 1e-3;
  const double error = ((*rotation) * rotation->transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kRotationTolerance) || rotation->determinant() <= 0.0) {
    return Status::DataLoss(path + ": 'T_BS.data' is not a rigid transform (its 3x3 part is not a rotation)");
  }
  return Status::Ok();
}

// Image sides beyond this are no camera's (the map file refuses them too).
constexpr double kMaxImageSide = 100000.0;

// A sensor.yaml's intrinsics (finite) and resolution (whole numbers of pixels up to kMaxImageSide).
Status ReadIntrinsics(const std::string& path, const YAML::Node& root, CameraIntrinsics* camera) {
  std::vector<double> intrinsics, resolution;
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["intrinsics"], "intrinsics", 4, &intrinsics));
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["resolution"], "resolution", 2, &resolution));
  if (!std::all_of(intrinsics.begin(), intrinsics.end(), [](double v) { return std::isfinite(v); })) {
    return Status::DataLoss(path + ": 'intrinsics' holds a value that is not a finite number");
  }
  for (const double side : resolution) {
    if (!(side >= 1.0 && side <= kMaxImageSide && side == std::floor(side))) {
      return Status::DataLoss(path + ": 'resolution' must be whole numbers of pixels from 1 to 100000");
    }
  }
  *camera = {intrinsics[0],
             intrinsics[1],
             intrinsics[2],
             intrinsics[3],
             static_cast<int>(resolution[0]),
             static_cast<int>(resolution[1])};
  if (!camera->valid()) return Status::DataLoss(path + ": intrinsics or resolution not positive");
  return Status::Ok();
}

// A sensor.yaml's radial-tangential distortion (k1, k2, p1, p2; none when absent). Another distortion model is
// valid but not undone: `unsupported` receives why, and `distortion` stays zero.
Status ReadDistortion(const std::string& path, const YAML::Node& root, Distortion* distortion,
                      std::string* unsupported) {
  if (root["distortion_model"]) {
    const std::string model = root["distortion_model"].IsScalar() ? root["distortion_model"].Scalar() : "";
    if (model != "radial-tangential" && model != "radtan") {
      *unsupported = path + ": distortion_model '" + model + "' is not radial-tangential, the only one undone";
      return Status::Ok();
    }
  }
  if (!root["distortion_coefficients"]) return Status::Ok();
  std::vector<double> coefficients;
  PATROLMAP_RETURN_IF_ERROR(
      ReadNumbers(path, root["distortion_coefficients"], "distortion_coefficients", 4, &coefficients));
  Distortion read;
  std::copy(coefficients.begin(), coefficients.begin() + 4, read.begin());
  if (!PlausibleDistortion(read)) {
    return Status::DataLoss(path + ": distortion_coefficients must be finite numbers of magnitude at most " +
                            std::to_string(static_cast<int>(kMaxDistortionCoefficient)));
  }
  *distortion = read;
  return Status::Ok();
}

// A camera of a stereo pair: its intrinsics, distortion and pose in the body frame.
struct StereoCamera {
  CameraIntrinsics intrinsics;
  Distortion distortion{};
  Eigen::Matrix3d body_rotation;
  Eigen::Vector3d body_translation;
};

// CAMERA/sensor.yaml for stereo matching: pinhole with radial-tangential distortion (k1, k2, p1, p2; none
// when absent). Another distortion model is valid but not matched: `unsupported` receives why.
Status ReadStereoCamera(const std::string& path, StereoCamera* camera, std::string* unsupported) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
  PATROLMAP_RETURN_IF_ERROR(ReadIntrinsics(path, root, &camera->intrinsics));
  PATROLMAP_RETURN_IF_ERROR(ReadDistortion(path, root, &camera->distortion, unsupported));
  return ReadBodyFromSensor(path, root, &camera->body_rotation, &camera->body_translation);
}

// The stereo pair of a log with cam1/ (both sensor.yaml and data.csv): its calibration, and one entry per cam0
// frame that cam1 saw at the same time (left and right image). Nothing when the log has no cam1/.
Status ReadStereoPairs(const std::string& log, const std::vector<ImageEntry>& left_entries,
                       std::optional<StereoCalibration>* calibration, std::vector<DepthEntry>* pairs) {
  if (!PathExists(log + "/cam1/data.csv") || !PathExists(log + "/cam1/sensor.yaml")) return Status::Ok();
  if (!PathExists(log + "/cam0/sensor.yaml")) {
    spdlog::warn("{}: cam1/ present but cam0/sensor.yaml missing: the stereo pair's calibration is unknown", log);
    return Status::Ok();
  }
  StereoCamera left, right;
  std::string unsupported;  // a camera model stereo matching does not undo
  PATROLMAP_RETURN_IF_ERROR(ReadStereoCamera(log + "/cam0/sensor.yaml", &left, &unsupported));
  PATROLMAP_RETURN_IF_ERROR(ReadStereoCamera(log + "/cam1/sensor.yaml", &right, &unsupported));
  if (!unsupported.empty()) {
    spdlog::warn("{}; the log's stereo pair is not used", unsupported);
    return Status::Ok();
  }
  StereoCalibration pair;
  pair.left = left.intrinsics;
  pair.right = right.intrinsics;
  pair.left_distortion = left.distortion;
  pair.right_distortion = right.distortion;
  // x_right = R_BC1^T (R_BC0 x_left + t_BC0 - t_BC1)
  pair.right_from_left_rotation = right.body_rotation.transpose() * left.body_rotation;
  pair.right_from_left_translation = right.body_rotation.transpose() * (left.body_translation - right.body_translation);
  std::vector<ImageEntry> right_entries;
  PATROLMAP_RETURN_IF_ERROR(ReadCameraTable(log, "cam1", &right_entries));
  auto right_entry = right_entries.begin();
  for (const ImageEntry& entry : left_entries) {
    while (right_entry != right_entries.end() && right_entry->timestamp_ns < entry.timestamp_ns) ++right_entry;
    if (right_entry == right_entries.end()) break;
    if (right_entry->timestamp_ns == entry.timestamp_ns)
      pairs->push_back({entry.timestamp_ns, entry.path, right_entry->path});
  }
  if (pairs->empty()) {
    spdlog::warn("{}: cam1/data.csv shares no timestamp with cam0/data.csv: no stereo pairs", log);
    return Status::Ok();
  }
  *calibration = pair;
  return Status::Ok();
}

Status ReadCameraSensor(const std::string& path, LogInfo* info, Eigen::Matrix3d* body_from_camera) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
  CameraIntrinsics camera;
  PATROLMAP_RETURN_IF_ERROR(ReadIntrinsics(path, root, &camera));
  info->camera = camera;
  std::string unsupported;
  PATROLMAP_RETURN_IF_ERROR(ReadDistortion(path, root, &info->camera_distortion, &unsupported));
  if (!unsupported.empty()) spdlog::warn("{}: route frames are matched as undistorted", unsupported);
  PATROLMAP_RETURN_IF_ERROR(ReadRate(path, root, "rate_hz", &info->frame_rate_hz));
  return ReadBodyFromSensor(path, root, body_from_camera);
}

Status ReadMeta(const std::string& path, LogInfo* info) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
  if (root["flight_id"] && !root["flight_id"].IsScalar()) return Status::DataLoss(path + ": 'flight_id' must be text");
  if (root["flight_id"]) info->flight_id = CleanFlightId(root["flight_id"].Scalar());
  return ReadRate(path, root, "frame_rate_hz", &info->frame_rate_hz);
}

Status ReadOptionalSensors(const std::string& log, LogInfo* info, std::vector<ImuSample>* imu,
                           std::vector<AttitudeSample>* attitude, std::vector<SpeedSample>* speeds) {
  Eigen::Matrix3d body_from_camera = Eigen::Matrix3d::Identity();
  const bool has_camera_yaml = PathExists(log + "/cam0/sensor.yaml");
  if (has_camera_yaml) {
    PATROLMAP_RETURN_IF_ERROR(ReadCameraSensor(log + "/cam0/sensor.yaml", info, &body_from_camera));
    info->body_from_camera = body_from_camera;
  }
  if (PathExists(log + "/meta.yaml")) PATROLMAP_RETURN_IF_ERROR(ReadMeta(log + "/meta.yaml", info));
  if (PathExists(log + "/imu0/data.csv")) {
    PATROLMAP_RETURN_IF_ERROR(ReadImuTable(log + "/imu0/data.csv", imu, attitude));
    Eigen::Matrix3d body_from_imu = Eigen::Matrix3d::Identity();
    if (PathExists(log + "/imu0/sensor.yaml")) {
      YAML::Node root;
      PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(log + "/imu0/sensor.yaml", &root));
      PATROLMAP_RETURN_IF_ERROR(ReadBodyFromSensor(log + "/imu0/sensor.yaml", root, &body_from_imu));
    }
    if (has_camera_yaml) info->camera_from_imu = body_from_camera.transpose() * body_from_imu;
  }
  const std::string state = log + "/state_groundtruth_estimate0/data.csv";
  if (PathExists(state)) PATROLMAP_RETURN_IF_ERROR(ReadSpeedTable(state, speeds));
  return Status::Ok();
}

// gps0/data.csv: timestamp, latitude [deg], longitude [deg], altitude [m].
Status ReadGpsTable(const std::string& path, std::vector<GpsSample>* samples) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, GpsSample* sample) {
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 1, "latitude, longitude, altitude", &sample->position));
    if (std::abs(sample->position.x()) > 90.0 || std::abs(sample->position.y()) > 180.0) {
      return csv.Error("latitude must lie in [-90, 90] and longitude in [-180, 180] degrees");
    }
    return Status::Ok();
  };
  return ReadTimedTable(path, 4, parse, samples);
}

std::vector<TimestampNs> FrameTimes(const std::vector<ImageEntry>& entries) {
  std::vector<TimestampNs> times(entries.size());
  std::transform(entries.begin(), entries.end(), times.begin(), [](const ImageEntry& e) { return e.timestamp_ns; });
  return times;
}

// Without a state estimate: camera poses from the GPS fixes and the IMU's attitude, at the frames' times.
void PosesFromFixes(const std::string& log, const LogInfo& info, const std::vector<GpsSample>& gps,
                    const std::vector<AttitudeSample>& attitude, const std::vector<ImageEntry>& entries,
                    PatrolSensors* sensors) {
  if (!info.camera_from_imu) {
    spdlog::warn(
        "{}: gps0/ and imu0/'s attitude, but cam0/sensor.yaml is missing (the camera's rotation in the "
        "IMU's frame): no camera poses from them",
        log);
    return;
  }
  sensors->poses =
      PosesFromGps(gps, attitude, Eigen::Quaterniond(info.camera_from_imu->transpose()), FrameTimes(entries));
  if (sensors->poses.empty()) {
    spdlog::warn("{}: gps0/ and imu0/'s attitude give no camera pose: their times do not cover cam0's", log);
    return;
  }
  sensors->pose_source = kPosesFromGps;
  const Eigen::Vector3d origin = GpsFrameOrigin(gps.front().position);
  spdlog::info(
      "{}: camera poses from gps0/ and imu0/'s attitude at {} of {} frames (east, north, up about "
      "{:.1f}, {:.1f} degrees)",
      log, sensors->poses.size(), entries.size(), origin.x(), origin.y());
}

}  // namespace

Status ReadCameraFile(const std::string& path, CameraIntrinsics* camera, Distortion* distortion) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
  PATROLMAP_RETURN_IF_ERROR(ReadIntrinsics(path, root, camera));
  std::string unsupported;
  *distortion = Distortion{};
  PATROLMAP_RETURN_IF_ERROR(ReadDistortion(path, root, distortion, &unsupported));
  return unsupported.empty() ? Status::Ok() : Status::InvalidArgument(unsupported);
}

Status OpenEuroc(const std::string& folder, std::unique_ptr<FrameSource>* source) {
  std::string log = folder;
  if (!PathExists(log + "/cam0/data.csv") && PathExists(log + "/mav0/cam0/data.csv")) log += "/mav0";
  LogInfo info;
  info.path = folder;
  info.kind = "euroc";
  // A EuRoC log keeps its data in mav0/: given as LOG/mav0, the flight is LOG's.
  std::error_code ignored;  // without a current folder the name as given serves
  fs::path named = fs::absolute(folder, ignored).lexically_normal();
  if (named.empty()) named = fs::path(folder).lexically_normal();
  if (!named.has_filename()) named = named.parent_path();
  if (named.filename() == "mav0" && named.has_parent_path()) named = named.parent_path();
  info.flight_id = CleanFlightId(named.filename().string());
  std::vector<ImageEntry> entries;
  std::vector<ImuSample> imu;
  std::vector<AttitudeSample> attitude;
  std::vector<SpeedSample> speeds;
  std::vector<GpsSample> gps;
  PATROLMAP_RETURN_IF_ERROR(ReadCameraTable(log, "cam0", &entries));
  PATROLMAP_RETURN_IF_ERROR(ReadOptionalSensors(log, &info, &imu, &attitude, &speeds));
  if (PathExists(log + "/gps0/data.csv")) PATROLMAP_RETURN_IF_ERROR(ReadGpsTable(log + "/gps0/data.csv", &gps));
  if (!(info.frame_rate_hz > 0.0 && std::isfinite(info.frame_rate_hz))) {
    info.frame_rate_hz = MedianRate(FrameTimes(entries));
  }
  info.timing = "cam0/data.csv";
  if (!imu.empty() && !info.camera_from_imu) {
    spdlog::warn("{}: imu0 present but cam0/sensor.yaml missing: camera-IMU rotation unknown", log);
  }
  PatrolSensors sensors;
  PATROLMAP_RETURN_IF_ERROR(
      ReadSensorTables(log, info.body_from_camera.value_or(Eigen::Matrix3d::Identity()), &sensors));
  PATROLMAP_RETURN_IF_ERROR(ReadStereoPairs(log, entries, &info.stereo, &sensors.stereo));
  if (sensors.poses.empty() && !gps.empty() && !attitude.empty())
    PosesFromFixes(log, info, gps, attitude, entries, &sensors);
  const bool calibrated = info.camera.has_value();
  auto images = std::make_unique<ImageListSource>(std::move(info), std::move(entries), std::move(imu),
                                                  std::move(speeds), std::move(gps), std::move(sensors));
  if (calibrated) PATROLMAP_RETURN_IF_ERROR(images->CheckResolution(*images->info().camera, log + "/cam0/sensor.yaml"));
  *source = std::move(images);
  return Status::Ok();
}

}  // namespace patrolmap::io
