#include "image_times.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

// Seconds in a decimal time with a fraction, or in a long integer by its size.
bool ParseTime(const std::string& text, double* seconds) {
  if (text.empty() || text.size() > 24 || std::count(text.begin(), text.end(), '.') > 1) return false;
  const std::size_t dot = text.find('.');
  const std::string digits = dot == std::string::npos ? text : text.substr(0, dot) + text.substr(dot + 1);
  if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return false;
  }
  const double value = std::stod(text);
  if (dot != std::string::npos) return *seconds = value, true;
  if (text.size() < 10 || text[0] == '0') return false;  // frame numbers such as 000123, not times
  const double divisor = text.size() >= 18 ? 1e9 : text.size() >= 15 ? 1e6 : text.size() >= 12 ? 1e3 : 1.0;
  *seconds = value / divisor;
  return true;
}

bool Increasing(const std::vector<TimestampNs>& times) {
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (times[i] <= times[i - 1]) return false;
  }
  return true;
}

Status ReadTimesFile(const std::string& path, std::size_t expected, std::vector<TimestampNs>* times) {
  std::ifstream file(path);
  if (!file) return Status::IoError(path + ": cannot read");
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    char* end = nullptr;
    const double seconds = std::strtod(line.c_str(), &end);
    if (end == line.c_str() || !std::isfinite(seconds) || seconds < 0.0 || seconds > 1e11) {
      return Status::DataLoss(path + ":" + std::to_string(number) + ": expected a time in seconds, got '" + line + "'");
    }
    times->push_back(SecondsToNs(seconds));
  }
  if (times->size() != expected) {
    return Status::DataLoss(path + ": " + std::to_string(times->size()) + " times for " + std::to_string(expected) +
                            " images");
  }
  if (!Increasing(*times)) return Status::DataLoss(path + ": times do not increase");
  return Status::Ok();
}

bool TimesFromNames(const std::vector<std::string>& paths, std::vector<TimestampNs>* times) {
  for (const std::string& path : paths) {
    double seconds = 0.0;
    if (!ParseTime(fs::path(path).stem().string(), &seconds)) return false;
    times->push_back(SecondsToNs(seconds));
  }
  return Increasing(*times);
}

}  // namespace

Status FindImageTimes(const std::string& folder, const std::vector<std::string>& paths,
                      std::vector<TimestampNs>* times, std::string* source) {
  times->clear();
  source->clear();
  const fs::path directory = fs::path(folder).lexically_normal();
  for (const fs::path& candidate : {directory / "times.txt", directory.parent_path() / "times.txt"}) {
    if (!fs::is_regular_file(candidate)) continue;
    PATROLMAP_RETURN_IF_ERROR(ReadTimesFile(candidate.string(), paths.size(), times));
    *source = candidate.string();
    return Status::Ok();
  }
  if (TimesFromNames(paths, times)) {
    *source = "file names";
    return Status::Ok();
  }
  times->clear();
  return Status::Ok();
}

double MedianRate(const std::vector<TimestampNs>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<TimestampNs> intervals(times.size() - 1);
  for (std::size_t i = 1; i < times.size(); ++i) intervals[i - 1] = times[i] - times[i - 1];
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  const TimestampNs median = intervals[intervals.size() / 2];
  return median > 0 ? 1e9 / static_cast<double>(median) : 0.0;
}

}  // namespace patrolmap::io
