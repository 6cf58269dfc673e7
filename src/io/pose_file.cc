#include "patrolmap/io/pose_file.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>

namespace patrolmap::io {
namespace {

constexpr int kTumValues = 8, kKittiValues = 12;

Status LineError(const std::string& path, int line, const std::string& problem) {
  return Status::DataLoss(path + ":" + std::to_string(line) + ": " + problem);
}

// The whitespace-separated numbers of `text`; false naming the first that is not a finite number.
bool ParseNumbers(const std::string& text, std::vector<double>* values, std::string* bad) {
  values->clear();
  std::istringstream stream(text);
  for (std::string token; stream >> token;) {
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size() || !std::isfinite(value)) return *bad = token, false;
    values->push_back(value);
  }
  return true;
}

Status TumPose(const std::string& path, int line, const std::vector<double>& v, CameraPoseSample* pose) {
  if (v[0] < 0.0 || v[0] > 9.2e9) return LineError(path, line, "timestamp must lie in [0, 9.2e9] s");
  const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  if (!(std::abs(q.norm() - 1.0) < 1e-2))
    return LineError(path, line, "the quaternion qx qy qz qw is not of unit length");
  pose->timestamp_ns = SecondsToNs(v[0]);
  pose->position = Eigen::Vector3d(v[1], v[2], v[3]);
  pose->rotation = q.normalized();
  return Status::Ok();
}

Status KittiPose(const std::string& path, int line, const std::vector<double>& v, TimestampNs time,
                 CameraPoseSample* pose) {
  Eigen::Matrix3d rotation;
  rotation << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
  if (!((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-3) ||
      !(rotation.determinant() > 0.0)) {
    return LineError(path, line, "the 3x3 part of the matrix is not a rotation");
  }
  pose->timestamp_ns = time;
  pose->position = Eigen::Vector3d(v[3], v[7], v[11]);
  pose->rotation = Eigen::Quaterniond(rotation).normalized();
  return Status::Ok();
}

}  // namespace

Status ReadPoseFile(const std::string& path, const std::vector<TimestampNs>& frame_times,
                    std::vector<CameraPoseSample>* poses) {
  poses->clear();
  std::ifstream file(path);
  if (!file) return Status::NotFound(path + ": cannot open pose file");
  int width = 0, number = 0;
  std::string text, bad;
  std::vector<double> values;
  while (std::getline(file, text)) {
    ++number;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const auto first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    if (!ParseNumbers(text, &values, &bad)) return LineError(path, number, "'" + bad + "' is not a finite number");
    const int count = static_cast<int>(values.size());
    if (width == 0 && count != kTumValues && count != kKittiValues) {
      return LineError(path, number,
                       std::to_string(count) +
                           " values; a pose line has 8 (TUM: t tx ty tz qx qy qz qw) or 12 "
                           "(KITTI: a 3x4 matrix)");
    }
    if (width != 0 && count != width) {
      return LineError(path, number, std::to_string(count) + " values, the lines before have " + std::to_string(width));
    }
    width = count;
    CameraPoseSample pose;
    if (width == kTumValues) {
      PATROLMAP_RETURN_IF_ERROR(TumPose(path, number, values, &pose));
      if (!poses->empty() && pose.timestamp_ns <= poses->back().timestamp_ns) {
        return LineError(path, number, "times must increase");
      }
    } else {
      if (poses->size() >= frame_times.size()) {
        return LineError(path, number,
                         "more KITTI poses than the log's " + std::to_string(frame_times.size()) +
                             " images (line i is the pose of image i)");
      }
      PATROLMAP_RETURN_IF_ERROR(KittiPose(path, number, values, frame_times[poses->size()], &pose));
    }
    poses->push_back(pose);
  }
  if (poses->empty()) return Status::DataLoss(path + ": no poses");
  if (width == kKittiValues && poses->size() != frame_times.size()) {
    return Status::DataLoss(path + ": " + std::to_string(poses->size()) + " KITTI poses for the log's " +
                            std::to_string(frame_times.size()) + " images (line i is the pose of image i)");
  }
  return Status::Ok();
}

}  // namespace patrolmap::io
