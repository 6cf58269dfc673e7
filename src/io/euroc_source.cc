// EuRoC/ASL flight-log reader (DESIGN.md "Flight logs").
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <spdlog/spdlog.h>
#include <Eigen/Geometry>

#include "euroc_tables.h"
#include "image_list_source.h"
#include "image_times.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/io/yaml_file.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

Status ReadCameraTable(const std::string& log, std::vector<ImageEntry>* entries) {
  const std::string path = log + "/cam0/data.csv";
  const auto parse = [&log](const CsvReader& csv, const std::vector<std::string_view>& fields, ImageEntry* entry) {
    std::string name;
    PATROLMAP_RETURN_IF_ERROR(ParseFileName(csv, fields[1], &name));
    entry->path = log + "/cam0/data/" + name;
    return Status::Ok();
  };
  PATROLMAP_RETURN_IF_ERROR(ReadTimedTable(path, 2, parse, entries));
  if (entries->empty()) return Status::DataLoss(path + ": no frames listed");
  return Status::Ok();
}

Status ReadImuTable(const std::string& path, std::vector<ImuSample>* samples) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, ImuSample* sample) {
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 1, "w_RS_S [rad s^-1]", &sample->gyro));
    return ParseVector(csv, fields, 4, "a_RS_S [m s^-2]", &sample->accel);
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
Status ReadRate(const std::string& path, const YAML::Node& root, const char* key, double* rate_hz) {
  if (!root[key]) return Status::Ok();
  double value = 0.0;
  try {
    value = root[key].as<double>();
  } catch (const YAML::Exception&) {
    value = 0.0;
  }
  if (!std::isfinite(value) || value <= 0.0) {
    return Status::DataLoss(path + ": '" + key + "' must be a frame rate above 0 [Hz]");
  }
  *rate_hz = value;
  return Status::Ok();
}

// Reads T_BS (body from sensor) of a sensor.yaml; identity when absent.
Status ReadBodyFromSensor(const std::string& path, const YAML::Node& root, Eigen::Matrix3d* rotation) {
  rotation->setIdentity();
  if (!root["T_BS"]) return Status::Ok();
  if (!root["T_BS"].IsMap()) return Status::DataLoss(path + ": 'T_BS' must be a map with 'data'");
  std::vector<double> data;
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["T_BS"]["data"], "T_BS.data", 16, &data));
  if (!std::all_of(data.begin(), data.end(), [](double v) { return std::isfinite(v); })) {
    return Status::DataLoss(path + ": 'T_BS.data' holds a value that is not a finite number");
  }
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) (*rotation)(row, col) = data[row * 4 + col];
  }
  return Status::Ok();
}

Status ReadCameraSensor(const std::string& path, LogInfo* info, Eigen::Matrix3d* body_from_camera) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
  std::vector<double> intrinsics, resolution;
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["intrinsics"], "intrinsics", 4, &intrinsics));
  PATROLMAP_RETURN_IF_ERROR(ReadNumbers(path, root["resolution"], "resolution", 2, &resolution));
  CameraIntrinsics camera{intrinsics[0],
                          intrinsics[1],
                          intrinsics[2],
                          intrinsics[3],
                          static_cast<int>(resolution[0]),
                          static_cast<int>(resolution[1])};
  if (!camera.valid()) return Status::DataLoss(path + ": intrinsics or resolution not positive");
  info->camera = camera;
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
                           std::vector<SpeedSample>* speeds) {
  Eigen::Matrix3d body_from_camera = Eigen::Matrix3d::Identity();
  const bool has_camera_yaml = fs::exists(log + "/cam0/sensor.yaml");
  if (has_camera_yaml) {
    PATROLMAP_RETURN_IF_ERROR(ReadCameraSensor(log + "/cam0/sensor.yaml", info, &body_from_camera));
    info->body_from_camera = body_from_camera;
  }
  if (fs::exists(log + "/meta.yaml")) PATROLMAP_RETURN_IF_ERROR(ReadMeta(log + "/meta.yaml", info));
  if (fs::exists(log + "/imu0/data.csv")) {
    PATROLMAP_RETURN_IF_ERROR(ReadImuTable(log + "/imu0/data.csv", imu));
    Eigen::Matrix3d body_from_imu = Eigen::Matrix3d::Identity();
    if (fs::exists(log + "/imu0/sensor.yaml")) {
      YAML::Node root;
      PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(log + "/imu0/sensor.yaml", &root));
      PATROLMAP_RETURN_IF_ERROR(ReadBodyFromSensor(log + "/imu0/sensor.yaml", root, &body_from_imu));
    }
    if (has_camera_yaml) info->camera_from_imu = body_from_camera.transpose() * body_from_imu;
  }
  const std::string state = log + "/state_groundtruth_estimate0/data.csv";
  if (fs::exists(state)) PATROLMAP_RETURN_IF_ERROR(ReadSpeedTable(state, speeds));
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

}  // namespace

Status OpenEuroc(const std::string& folder, std::unique_ptr<FrameSource>* source) {
  std::string log = folder;
  if (!fs::exists(log + "/cam0/data.csv") && fs::exists(log + "/mav0/cam0/data.csv")) log += "/mav0";
  LogInfo info;
  info.path = folder;
  info.kind = "euroc";
  info.flight_id = fs::path(folder).lexically_normal().filename().string();
  if (info.flight_id.empty()) info.flight_id = fs::path(folder).parent_path().filename().string();
  info.flight_id = CleanFlightId(info.flight_id);
  std::vector<ImageEntry> entries;
  std::vector<ImuSample> imu;
  std::vector<SpeedSample> speeds;
  std::vector<GpsSample> gps;
  PATROLMAP_RETURN_IF_ERROR(ReadCameraTable(log, &entries));
  PATROLMAP_RETURN_IF_ERROR(ReadOptionalSensors(log, &info, &imu, &speeds));
  if (fs::exists(log + "/gps0/data.csv")) PATROLMAP_RETURN_IF_ERROR(ReadGpsTable(log + "/gps0/data.csv", &gps));
  if (!(info.frame_rate_hz > 0.0 && std::isfinite(info.frame_rate_hz))) {
    std::vector<TimestampNs> times(entries.size());
    std::transform(entries.begin(), entries.end(), times.begin(), [](const ImageEntry& e) { return e.timestamp_ns; });
    info.frame_rate_hz = MedianRate(times);
  }
  info.timing = "cam0/data.csv";
  if (!imu.empty() && !info.camera_from_imu) {
    spdlog::warn("{}: imu0 present but cam0/sensor.yaml missing: camera-IMU rotation unknown", log);
  }
  PatrolSensors sensors;
  PATROLMAP_RETURN_IF_ERROR(
      ReadSensorTables(log, info.body_from_camera.value_or(Eigen::Matrix3d::Identity()), &sensors));
  *source = std::make_unique<ImageListSource>(std::move(info), std::move(entries), std::move(imu), std::move(speeds),
                                              std::move(gps), std::move(sensors));
  return Status::Ok();
}

}  // namespace patrolmap::io
