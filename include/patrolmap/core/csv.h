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

// Splits `line` at commas, trimming spaces, tabs and a trailing '\r'.
void SplitCsvLine(std::string_view line, std::vector<std::string_view>* fields);

}  // namespace patrolmap
