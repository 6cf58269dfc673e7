#include "patrolmap/io/ground_truth.h"

#include "patrolmap/io/csv.h"

namespace patrolmap::io {

Status ReadTruthKeyLocations(const std::string& log, std::vector<TruthKeyLocationRecord>* truth) {
  truth->clear();
  CsvReader csv;
  PATROLMAP_RETURN_IF_ERROR(csv.Open(log + "/groundtruth/key_locations.csv"));
  std::vector<std::string_view> fields;
  Status status;
  while ((status = csv.NextRow(&fields)).ok()) {
    if (fields.size() < 3) return csv.Error("expected at least 3 columns");
    TruthKeyLocationRecord record;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[0], "timestamp [ns]", &record.timestamp_ns));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[1], "frame_index", &record.frame_index));
    if (fields[2] != "opening" && fields[2] != "closing") return csv.Error("kind must be opening or closing");
    record.opening = fields[2] == "opening";
    truth->push_back(record);
  }
  return status.end_of_stream() ? Status::Ok() : status;
}

}  // namespace patrolmap::io
