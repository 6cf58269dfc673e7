#include "image_times.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

// Digits known to fit (at most 11): their value.
long long ToInteger(const std::string& digits) {
  long long value = 0;
  std::from_chars(digits.data(), digits.data() + digits.size(), value);
  return value;
}

// The time a file stem names, exactly in nanoseconds: decimal seconds with a fraction, or an integer of
// at least 10 digits read as seconds, milliseconds, microseconds or nanoseconds by its length.
bool ParseTime(const std::string& text, TimestampNs* ns) {
  const std::size_t dot = text.find('.');
  const std::string whole = text.substr(0, dot);
  const std::string fraction = dot == std::string::npos ? "" : text.substr(dot + 1);
  const auto digits = [](const std::string& part) {
    return std::all_of(part.begin(), part.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  if (whole.empty() || whole.size() > 19 || !digits(whole) || !digits(fraction)) return false;
  if (dot != std::string::npos) {
    if (fraction.empty() || whole.size() > 11) return false;
    const std::string nanos = (fraction + "000000000").substr(0, 9);
    const long long seconds = ToInteger(whole);
    if (seconds > kMaxTimestampNs / 1000000000LL) return false;  // beyond the valid times (and 2^63 ns)
    *ns = seconds * 1000000000LL + ToInteger(nanos);
    return ValidTimestamp(*ns);
  }
  if (whole.size() < 10 || whole[0] == '0') return false;  // frame numbers such as 000123, not times
  long long value = 0;
  if (std::from_chars(whole.data(), whole.data() + whole.size(), value).ec != std::errc()) return false;  // > 2^63
  const long long factor = whole.size() >= 18   ? 1
                           : whole.size() >= 15 ? 1000
                           : whole.size() >= 12 ? 1000000
                                                : 1000000000;
  if (value > kMaxTimestampNs / factor) return false;
  *ns = value * factor;
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
    if (end == line.c_str() || !std::isfinite(seconds) || seconds < 0.0 || seconds > NsToSeconds(kMaxTimestampNs)) {
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
    TimestampNs ns = 0;
    if (!ParseTime(fs::path(path).stem().string(), &ns)) return false;
    times->push_back(ns);
  }
  return Increasing(*times);
}

}  // namespace

Status FindImageTimes(const std::string& folder, const std::vector<std::string>& paths, std::vector<TimestampNs>* times,
                      std::string* source) {
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
