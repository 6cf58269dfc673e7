#include "patrolmap/core/csv.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>

namespace patrolmap {
namespace {

std::string_view Trim(std::string_view text) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

}  // namespace

void SplitCsvLine(std::string_view line, std::vector<std::string_view>* fields) {
  fields->clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields->push_back(Trim(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos) return;
    start = comma + 1;
  }
}

Status CsvReader::Open(const std::string& path) {
  path_ = path;
  line_number_ = 0;
  if (!std::filesystem::is_regular_file(path)) return Status::NotFound(path + ": no such file");
  stream_.open(path);
  if (!stream_) return Status::IoError(path + ": cannot open for reading");
  return Status::Ok();
}

Status CsvReader::NextRow(std::vector<std::string_view>* fields) {
  while (std::getline(stream_, line_)) {
    ++line_number_;
    const std::string_view trimmed = Trim(line_);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    SplitCsvLine(trimmed, fields);
    return Status::Ok();
  }
  if (stream_.bad()) return Error("read failed");
  return Status::EndOfStream();
}

Status CsvReader::Error(const std::string& message) const {
  return Status::DataLoss(path_ + ":" + std::to_string(line_number_) + ": " + message);
}

Status CsvReader::ParseInt64(std::string_view field, const char* column, std::int64_t* value) const {
  const char* end = field.data() + field.size();
  const auto result = std::from_chars(field.data(), end, *value);
  if (field.empty() || result.ec != std::errc() || result.ptr != end) {
    return Error(std::string("column '") + column + "': not an integer: '" + std::string(field) + "'");
  }
  return Status::Ok();
}

Status CsvReader::ParseDouble(std::string_view field, const char* column, double* value) const {
  const std::string text(field);
  char* end = nullptr;
  errno = 0;
  *value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) {
    return Error(std::string("column '") + column + "': not a number: '" + text + "'");
  }
  if (!std::isfinite(*value)) return Error(std::string("column '") + column + "': not a finite number: '" + text + "'");
  return Status::Ok();
}

}  // namespace patrolmap
