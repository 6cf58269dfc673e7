// Internal: helpers for EuRoC-style tables whose first column is a timestamp.
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "patrolmap/core/csv.h"
#include "patrolmap/core/types.h"

namespace patrolmap::io {

inline Status CheckColumns(const CsvReader& csv, const std::vector<std::string_view>& fields, std::size_t minimum) {
  if (fields.size() >= minimum) return Status::Ok();
  return csv.Error("expected at least " + std::to_string(minimum) + " columns, found " + std::to_string(fields.size()));
}

inline Status CheckIncreasing(const CsvReader& csv, TimestampNs previous, TimestampNs current, bool strict = true) {
  if (current > previous || (!strict && current == previous)) return Status::Ok();
  return csv.Error("timestamp " + std::to_string(current) + (strict ? " is not after" : " is before") +
                   " the previous one (" + std::to_string(previous) + ")");
}

// Reads a table whose first column is an increasing timestamp [ns] (strictly,
// unless several rows may share a time); `parse_row(csv, fields, &row)` fills
// the other columns of each row.
template <typename Row, typename ParseRow>
Status ReadTimedTable(const std::string& path, std::size_t columns, ParseRow parse_row, std::vector<Row>* rows,
                      bool strict = true) {
  CsvReader csv;
  PATROLMAP_RETURN_IF_ERROR(csv.Open(path));
  std::vector<std::string_view> fields;
  Status status;
  TimestampNs previous = std::numeric_limits<TimestampNs>::min();
  while ((status = csv.NextRow(&fields)).ok()) {
    PATROLMAP_RETURN_IF_ERROR(CheckColumns(csv, fields, columns));
    Row row;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[0], "timestamp [ns]", &row.timestamp_ns));
    if (!ValidTimestamp(row.timestamp_ns)) {
      return csv.Error("timestamp " + std::to_string(row.timestamp_ns) + " is outside 0.." +
                       std::to_string(kMaxTimestampNs) + " ns");
    }
    PATROLMAP_RETURN_IF_ERROR(CheckIncreasing(csv, previous, row.timestamp_ns, strict));
    PATROLMAP_RETURN_IF_ERROR(parse_row(csv, fields, &row));
    previous = row.timestamp_ns;
    rows->push_back(std::move(row));
  }
  return status.end_of_stream() ? Status::Ok() : status;
}

// A table's file name, relative to its data folder: refused when empty or when it would leave the folder
// (absolute, or ".." above it), so a log cannot make patrolmap read files elsewhere.
inline Status ParseFileName(const CsvReader& csv, std::string_view field, std::string* name) {
  if (field.empty()) return csv.Error("empty file name");
  const std::filesystem::path path = std::filesystem::path(std::string(field)).lexically_normal();
  if (path.is_absolute() || path.empty() || *path.begin() == "..") {
    return csv.Error("file name '" + std::string(field) + "' leaves the log's data folder");
  }
  *name = std::string(field);
  return Status::Ok();
}

inline Status ParseVector(const CsvReader& csv, const std::vector<std::string_view>& fields, std::size_t first,
                          const char* column, Eigen::Vector3d* vector) {
  for (int axis = 0; axis < 3; ++axis) {
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[first + axis], column, &(*vector)[axis]));
  }
  return Status::Ok();
}

// Four columns from `first` on as a quaternion w, x, y, z, which must have unit length (within 1e-3); returned
// normalised.
inline Status ParseUnitQuaternion(const CsvReader& csv, const std::vector<std::string_view>& fields, std::size_t first,
                                  const char* column, Eigen::Quaterniond* quaternion) {
  double q[4];
  for (int i = 0; i < 4; ++i) PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[first + i], column, &q[i]));
  const Eigen::Quaterniond parsed(q[0], q[1], q[2], q[3]);
  if (!(std::abs(parsed.norm() - 1.0) <= 1e-3)) return csv.Error(std::string(column) + " is not a unit quaternion");
  *quaternion = parsed.normalized();
  return Status::Ok();
}

}  // namespace patrolmap::io
