// A small strict CSV reader for flight-log tables (EuRoC's data.csv files).
// Lines starting with '#' and blank lines are skipped; every error names the
// file and the 1-based line number.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "patrolmap/core/status.h"

namespace patrolmap {

class CsvReader {
 public:
  // Opens `path`; fails with NotFound when it does not exist.
  Status Open(const std::string& path);

  // Reads the next data row into `fields` (whitespace around fields trimmed).
  // Returns EndOfStream after the last row.
  Status NextRow(std::vector<std::string_view>* fields);

  // Error naming the file and the current line: "path:line: message".
  Status Error(const std::string& message) const;

  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }

  // Field parsers; they fail with an Error() naming the column.
  Status ParseInt64(std::string_view field, const char* column, std::int64_t* value) const;
  Status ParseDouble(std::string_view field, const char* column, double* value) const;

 private:
  std::string path_;
  std::ifstream stream_;
  std::string line_;
  int line_number_ = 0;
};

// Characters a CSV row of patrolmap cannot hold inside a field (control characters, commas, double quotes):
// the one rule flight ids are cleaned with (io::CleanFlightId) and checked against (map files).
inline bool BreaksCsvField(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u < 0x20 || u == 0x7f || c == ',' || c == '"';
}

// Splits `line` at commas, trimming spaces, tabs and a trailing '\r'.
void SplitCsvLine(std::string_view line, std::vector<std::string_view>* fields);

// Reads a table row by row with `parse(csv, fields, &row)`. With a
// `first_column`, the first row is a header that must start with it (as
// patrolmap writes its outputs); with nullptr every row is data (headers are
// '#' comments, as in EuRoC tables and the simulator's ground truth).
template <typename Row, typename Parse>
Status ReadTable(const std::string& path, const char* first_column, Parse parse, std::vector<Row>* rows) {
  rows->clear();
  CsvReader csv;
  PATROLMAP_RETURN_IF_ERROR(csv.Open(path));
  std::vector<std::string_view> fields;
  Status status;
  if (first_column != nullptr) {
    status = csv.NextRow(&fields);
    if (!status.ok()) return status.end_of_stream() ? csv.Error("empty file: no header") : status;
    if (fields.empty() || fields[0] != first_column) {
      return csv.Error(std::string("header must start with '") + first_column + "'");
    }
  }
  while ((status = csv.NextRow(&fields)).ok()) {
    Row row;
    PATROLMAP_RETURN_IF_ERROR(parse(csv, fields, &row));
    rows->push_back(std::move(row));
  }
  return status.end_of_stream() ? Status::Ok() : status;
}

}  // namespace patrolmap
