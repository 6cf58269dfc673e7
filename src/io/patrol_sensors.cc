#include "patrolmap/io/patrol_sensors.h"

#include <algorithm>
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>
#include <opencv2/imgcodecs.hpp>

#include "euroc_tables.h"
#include "patrolmap/core/files.h"
#include "patrolmap/io/readers.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

Status ReadPoseTable(const std::string& path, const Eigen::Matrix3d& body_from_camera,
                     std::vector<CameraPoseSample>* poses) {
  const Eigen::Quaterniond camera_rotation(body_from_camera);
  const auto parse = [&camera_rotation](const CsvReader& csv, const std::vector<std::string_view>& fields,
                                        CameraPoseSample* pose) {
    PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 1, "p_RS_R [m]", &pose->position));
    Eigen::Quaterniond body;
    PATROLMAP_RETURN_IF_ERROR(ParseUnitQuaternion(csv, fields, 4, "q_RS", &body));
    pose->rotation = (body * camera_rotation).normalized();
    return Status::Ok();
  };
  return ReadTimedTable(path, 8, parse, poses);
}

Status ReadDetectionTable(const std::string& path, std::vector<ObjectObservation>* detections) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, ObjectObservation* o) {
    if (fields[1].empty()) return csv.Error("empty label");
    o->label = std::string(fields[1]);
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[2], "confidence", &o->confidence));
    if (!(o->confidence >= 0.0 && o->confidence <= 1.0)) return csv.Error("confidence must lie in [0, 1]");
    double box[4];
    for (int i = 0; i < 4; ++i) PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[3 + i], "box [px]", &box[i]));
    if (!(box[2] > box[0] && box[3] > box[1])) return csv.Error("box must have x_max > x_min and y_max > y_min");
    o->box = cv::Rect2d(box[0], box[1], box[2] - box[0], box[3] - box[1]);
    if (fields.size() > 7 && fields.size() < 10) {
      return csv.Error("a centroid needs three values (x, y, z [m]) after the box; found " +
                       std::to_string(fields.size() - 7));
    }
    if (fields.size() >= 10) {
      Eigen::Vector3d centroid;
      PATROLMAP_RETURN_IF_ERROR(ParseVector(csv, fields, 7, "centroid [m]", &centroid));
      o->centroid_camera = centroid;
    }
    return Status::Ok();
  };
  return ReadTimedTable(path, 7, parse, detections, /*strict=*/false);
}

Status ReadDepthTable(const std::string& log, std::vector<DepthEntry>* entries) {
  const auto parse = [&log](const CsvReader& csv, const std::vector<std::string_view>& fields, DepthEntry* entry) {
    std::string name;
    PATROLMAP_RETURN_IF_ERROR(ParseFileName(csv, fields[1], &name));
    entry->path = log + "/depth0/data/" + name;
    return Status::Ok();
  };
  PATROLMAP_RETURN_IF_ERROR(ReadTimedTable(log + "/depth0/data.csv", 2, parse, entries));
  // Depth is read at the grid's rate, so a missing file might never be noticed: each is checked here, and
  // the missing ones are dropped with one warning that names the first.
  const std::size_t listed = entries->size();
  std::string first_missing;
  entries->erase(std::remove_if(entries->begin(), entries->end(),
                                [&first_missing](const DepthEntry& entry) {
                                  if (std::filesystem::is_regular_file(entry.path)) return false;
                                  if (first_missing.empty()) first_missing = entry.path;
                                  return true;
                                }),
                 entries->end());
  if (entries->size() < listed) {
    spdlog::warn("{}/depth0/data.csv: {} of the {} depth images it lists are missing (the first: {}); they are skipped",
                 log, listed - entries->size(), listed, first_missing);
  }
  return Status::Ok();
}

}  // namespace

Status ReadPatrolSensors(const std::string& log, PatrolSensors* sensors) {
  *sensors = PatrolSensors();
  std::unique_ptr<FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(OpenLog(log, ImageFolderOptions{}, &source));
  const LogInfo& info = source->info();
  sensors->flight_id = info.flight_id;
  sensors->camera = info.camera;
  if (info.kind != "euroc") return Status::Ok();
  std::string root = log;
  if (!PathExists(root + "/cam0/data.csv") && PathExists(root + "/mav0/cam0/data.csv")) root += "/mav0";
  return ReadSensorTables(root, info.body_from_camera.value_or(Eigen::Matrix3d::Identity()), sensors);
}

Status ReadSensorTables(const std::string& root, const Eigen::Matrix3d& body_from_camera, PatrolSensors* sensors) {
  const std::string state = root + "/state_groundtruth_estimate0/data.csv";
  if (PathExists(state)) {
    PATROLMAP_RETURN_IF_ERROR(ReadPoseTable(state, body_from_camera, &sensors->poses));
    if (!sensors->poses.empty()) sensors->pose_source = kPosesFromStateEstimate;
  }
  if (PathExists(root + "/objects0/data.csv")) {
    PATROLMAP_RETURN_IF_ERROR(ReadDetectionTable(root + "/objects0/data.csv", &sensors->detections));
  }
  if (PathExists(root + "/depth0/data.csv")) PATROLMAP_RETURN_IF_ERROR(ReadDepthTable(root, &sensors->depth));
  return Status::Ok();
}

std::optional<CameraPoseSample> PoseAt(const std::vector<CameraPoseSample>& poses, TimestampNs timestamp_ns,
                                       TimestampNs max_gap_ns) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), timestamp_ns,
                                      [](const CameraPoseSample& p, TimestampNs t) { return p.timestamp_ns < t; });
  if (after == poses.end()) return std::nullopt;
  if (after->timestamp_ns == timestamp_ns) return *after;
  if (after == poses.begin()) return std::nullopt;
  const CameraPoseSample& before = *(after - 1);
  if (after->timestamp_ns - before.timestamp_ns > max_gap_ns) return std::nullopt;
  const double s = static_cast<double>(timestamp_ns - before.timestamp_ns) /
                   static_cast<double>(after->timestamp_ns - before.timestamp_ns);
  CameraPoseSample pose;
  pose.timestamp_ns = timestamp_ns;
  pose.position = (1.0 - s) * before.position + s * after->position;
  pose.rotation = before.rotation.slerp(s, after->rotation);
  return pose;
}

Status ReadDepthImage(const std::string& path, cv::Mat* depth_m) {
  if (!PathExists(path)) return Status::NotFound(path + ": depth image missing");
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty()) return Status::DataLoss(path + ": cannot decode depth image");
  if (raw.type() != CV_16UC1) return Status::DataLoss(path + ": depth image must be 16-bit single-channel");
  raw.convertTo(*depth_m, CV_32FC1, 1e-3);
  return Status::Ok();
}

}  // namespace patrolmap::io
