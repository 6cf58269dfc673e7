// Image-folder, printf-pattern and video readers, and the choice between readers.
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include <spdlog/spdlog.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "image_list_source.h"
#include "image_times.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/sqlite.h"
#include "patrolmap/io/bag.h"
#include "patrolmap/io/natural_sort.h"
#include "patrolmap/io/readers.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

bool IsImageFile(const fs::path& path) {
  static const std::array<const char*, 8> kExtensions = {".png", ".jpg", ".jpeg", ".bmp",
                                                         ".pgm", ".ppm", ".tif",  ".tiff"};
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return std::find(kExtensions.begin(), kExtensions.end(), extension) != kExtensions.end();
}

Status CheckFrameRate(const ImageFolderOptions& options) {
  if (std::isfinite(options.frame_rate_hz) && options.frame_rate_hz >= 0.0 && options.frame_rate_hz <= 10000.0) {
    return Status::Ok();
  }
  return Status::InvalidArgument("frame rate = " + std::to_string(options.frame_rate_hz) +
                                 ": must be in [0, 10000] Hz (0: from the log)");
}

// The rate the user gave, else `log_rate` when the log has one, else the assumed rate (LogInfo::timed false).
double ChooseRate(const ImageFolderOptions& options, double log_rate, LogInfo* info) {
  if (options.frame_rate_hz > 0.0) {
    info->timing = "given rate " + std::to_string(options.frame_rate_hz) + " Hz";
    return options.frame_rate_hz;
  }
  if (log_rate > 0.0) return log_rate;
  info->timed = false;
  info->timing = "no timestamps";
  return kAssumedFrameRateHz;
}

std::vector<ImageEntry> TimestampAtRate(const std::vector<std::string>& paths, double rate_hz) {
  std::vector<ImageEntry> entries(paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i) {
    entries[i] = {SecondsToNs(static_cast<double>(i) / rate_hz), paths[i]};
  }
  return entries;
}

// Entries of an image list: at the given rate, else at the list's own times, else at the assumed rate.
std::vector<ImageEntry> TimedEntries(const std::vector<std::string>& paths, const std::vector<TimestampNs>& times,
                                     const ImageFolderOptions& options, LogInfo* info) {
  const double rate = ChooseRate(options, MedianRate(times), info);
  info->frame_rate_hz = rate;
  if (options.frame_rate_hz > 0.0 || times.size() != paths.size()) return TimestampAtRate(paths, rate);
  std::vector<ImageEntry> entries(paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i) entries[i] = {times[i] - times.front(), paths[i]};
  return entries;
}

// A printf pattern with one integer conversion (%d, %i or %u with optional 0 flag and width, e.g.
// %05d); %% stands for a percent sign. Anything else is refused: the pattern comes from the user.
struct ImagePattern {
  std::string prefix, suffix;
  bool zero_pad = false;
  int width = 0;

  std::string Format(int index) const {
    std::string number = std::to_string(index);
    if (static_cast<int>(number.size()) < width) number.insert(0, width - number.size(), zero_pad ? '0' : ' ');
    return prefix + number + suffix;
  }
};

Status ParsePattern(const std::string& pattern, ImagePattern* parsed) {
  const auto bad = [&pattern](const std::string& why) {
    return Status::InvalidArgument(pattern + ": not an image pattern: " + why +
                                   " (expected one %d, %05d or similar; %% for a percent sign)");
  };
  bool found = false;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    std::string& out = found ? parsed->suffix : parsed->prefix;
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    if (found) return bad("more than one conversion");
    std::size_t j = i + 1;
    if (j < pattern.size() && pattern[j] == '0') parsed->zero_pad = true, ++j;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j])) && parsed->width < 100) {
      parsed->width = parsed->width * 10 + (pattern[j++] - '0');
    }
    if (j >= pattern.size() || std::string("diu").find(pattern[j]) == std::string::npos || parsed->width > 20) {
      return bad("unsupported conversion '" + pattern.substr(i, j - i + 1) + "'");
    }
    found = true;
    i = j;
  }
  if (!found) return bad("no conversion");
  return Status::Ok();
}

// Reads frames from a video or a camera; unreadable frames end the stream (codecs cannot resync). A video's
// frames are timed by their index and rate, a camera's by the clock since the first.
class VideoSource : public FrameSource {
 public:
  VideoSource(LogInfo info, cv::VideoCapture capture, bool live = false)
      : info_(std::move(info)), capture_(std::move(capture)), live_(live) {}

  Status Next(bool decode_image, Frame* frame) override {
    frame->imu.clear();
    frame->image.release();
    if (!capture_.grab()) {
      WarnIfTruncated();
      return Status::EndOfStream();
    }
    frame->index = next_index_++;
    frame->timestamp_ns = SecondsToNs(static_cast<double>(frame->index) / info_.frame_rate_hz);
    if (live_) {
      const auto now = std::chrono::steady_clock::now();
      if (frame->index == 0) start_ = now;
      frame->timestamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_).count();
    }
    frame->colour.release();
    if (decode_image) {
      capture_.retrieve(buffer_);
      if (buffer_.channels() == 1) {
        buffer_.copyTo(frame->image);
      } else {
        cv::cvtColor(buffer_, frame->image, cv::COLOR_BGR2GRAY);
        if (keep_colour() && buffer_.type() == CV_8UC3) frame->colour = buffer_;  // valid until the next read
      }
    }
    return Status::Ok();
  }
  const LogInfo& info() const override { return info_; }
  void SetFlightId(std::string id) override { info_.flight_id = std::move(id); }

 private:
  // A video that ends well before the frame count of its header was cut short (a copy or a recording
  // interrupted): its frames up to the cut are used, and the user is told once. Containers estimate the
  // count from the duration, so a shortfall of up to 1 % (at least 2 frames) is not reported.
  void WarnIfTruncated() {
    if (live_ || warned_ || info_.frame_count <= 0) return;
    warned_ = true;
    const std::int64_t tolerance = std::max<std::int64_t>(2, info_.frame_count / 100);
    if (next_index_ + tolerance >= info_.frame_count) return;
    spdlog::warn("{}: the video ends after {} of the {} frames its header lists (truncated?); the rest is missing",
                 info_.path, next_index_, info_.frame_count);
  }

  LogInfo info_;
  bool warned_ = false;
  cv::VideoCapture capture_;
  bool live_ = false;
  std::chrono::steady_clock::time_point start_;
  cv::Mat buffer_;
  std::int64_t next_index_ = 0;
};

LogInfo MakeInfo(const std::string& path, const char* kind, double frame_rate_hz) {
  LogInfo info;
  info.path = path;
  info.kind = kind;
  info.flight_id = CleanFlightId(fs::path(path).lexically_normal().filename().string());
  info.frame_rate_hz = frame_rate_hz;
  return info;
}

}  // namespace

Status OpenImageFolder(const std::string& folder, const ImageFolderOptions& options,
                       std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  if (!fs::is_directory(folder)) return Status::NotFound(folder + ": no such folder");
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& item : fs::directory_iterator(folder, error)) {
    std::error_code unreadable;  // a link into a loop, or to nowhere, is no image
    if (item.is_regular_file(unreadable) && IsImageFile(item.path())) names.push_back(item.path().filename());
  }
  if (error) return Status::IoError(folder + ": cannot list: " + error.message());
  if (names.empty() && (PathExists(folder + "/cam0") || PathExists(folder + "/mav0/cam0"))) {
    return Status::DataLoss(folder + ": a EuRoC log without its camera table (cam0/data.csv: timestamp [ns],filename)");
  }
  if (names.empty()) return Status::DataLoss(folder + ": folder holds no images (.png, .jpg, ...)");
  NaturalSort(&names);
  for (std::string& name : names) name = (fs::path(folder) / name).string();
  std::vector<TimestampNs> times;
  LogInfo info = MakeInfo(folder, "image-folder", 0.0);
  PATROLMAP_RETURN_IF_ERROR(FindImageTimes(folder, names, &times, &info.timing));
  if (!times.empty()) info.timing = "times from " + info.timing;
  std::vector<ImageEntry> entries = TimedEntries(names, times, options, &info);
  *source = std::make_unique<ImageListSource>(std::move(info), std::move(entries));
  return Status::Ok();
}

Status OpenImagePattern(const std::string& pattern, const ImageFolderOptions& options,
                        std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  ImagePattern parsed;
  PATROLMAP_RETURN_IF_ERROR(ParsePattern(pattern, &parsed));
  const int first = PathExists(parsed.Format(0)) ? 0 : 1;
  std::vector<std::string> paths;
  for (int index = first; index < std::numeric_limits<int>::max() && PathExists(parsed.Format(index)); ++index) {
    paths.push_back(parsed.Format(index));
  }
  if (paths.empty()) {
    return Status::NotFound(pattern + ": no file matches the pattern (tried " + parsed.Format(0) + " and " +
                            parsed.Format(1) + ")");
  }
  LogInfo info = MakeInfo(pattern, "image-pattern", 0.0);
  std::vector<ImageEntry> entries = TimedEntries(paths, {}, options, &info);
  *source = std::make_unique<ImageListSource>(std::move(info), std::move(entries));
  return Status::Ok();
}

// Refuses, by its first bytes, a file that is plainly no video before a decoder (and its library's traces) sees it:
// patrolmap's own maps and vocabularies, single images, and text (configurations, tables).
Status RefuseNonVideo(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  char head[512] = {};
  stream.read(head, sizeof(head));
  const std::string start(head, static_cast<std::size_t>(stream.gcount()));
  const auto starts = [&](const std::string& magic) { return start.compare(0, magic.size(), magic) == 0; };
  if (start.empty()) return Status::DataLoss(path + ": an empty file, not a flight log");
  // A map of format 13 on is an SQLite database with a map_info table; format 12 and older began "PMMAP".
  SqliteDatabase database;
  const bool sqlite = starts(std::string("SQLite format 3\0", 16));
  if (starts(std::string("PMMAP\0", 6)) ||
      (sqlite && SqliteDatabase::Open(path, SqliteDatabase::Mode::kReadOnly, &database).ok() &&
       database.HasTable("map_info"))) {
    return Status::InvalidArgument(path + ": a patrolmap map, not a flight log (give a map with --map)");
  }
  if (sqlite) {
    return Status::InvalidArgument(path +
                                   ": an SQLite database, not a flight log (a ROS 2 bag is read from its "
                                   "folder, the one that holds metadata.yaml)");
  }
  if (starts("PMVOCAB")) {
    return Status::InvalidArgument(path + ": a patrolmap vocabulary, not a flight log (give it with --vocabulary)");
  }
  std::string extension = fs::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::set<std::string> image_extensions = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"};
  if (image_extensions.count(extension) != 0 && !starts("\0")) {
    return Status::InvalidArgument(path + ": a single image, not a flight log; give the folder that holds the images");
  }
  const bool text = std::all_of(start.begin(), start.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u >= 0x20 || c == '\n' || c == '\r' || c == '\t';
  });
  if (text) {
    return Status::InvalidArgument(path +
                                   ": a text file (a configuration or a table?), not a flight log; a EuRoC log is the "
                                   "folder that holds cam0/, an image collection the folder of its images");
  }
  return Status::Ok();
}

Status OpenVideo(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  if (!fs::is_regular_file(path)) return Status::NotFound(path + ": no such file");
  PATROLMAP_RETURN_IF_ERROR(RefuseNonVideo(path));
  cv::VideoCapture capture(path);
  if (!capture.isOpened()) return Status::DataLoss(path + ": not a video OpenCV can decode");
  const double reported_rate = capture.get(cv::CAP_PROP_FPS);
  LogInfo info = MakeInfo(path, "video", 0.0);
  info.timing = "the video's frame rate";
  info.frame_rate_hz = ChooseRate(options, std::isfinite(reported_rate) ? reported_rate : 0.0, &info);
  const double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
  info.frame_count = count > 0.0 ? static_cast<std::int64_t>(count) : -1;
  *source = std::make_unique<VideoSource>(std::move(info), std::move(capture));
  return Status::Ok();
}

Status OpenCamera(int device, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  cv::VideoCapture capture(device);
  if (!capture.isOpened()) return Status::NotFound("camera " + std::to_string(device) + ": cannot be opened");
  const double reported_rate = capture.get(cv::CAP_PROP_FPS);
  LogInfo info = MakeInfo("camera" + std::to_string(device), "camera", 0.0);
  info.timing = "the camera's clock";
  info.frame_rate_hz = options.frame_rate_hz > 0.0                           ? options.frame_rate_hz
                       : std::isfinite(reported_rate) && reported_rate > 0.0 ? reported_rate
                                                                             : kAssumedFrameRateHz;
  *source = std::make_unique<VideoSource>(std::move(info), std::move(capture), true);
  return Status::Ok();
}

Status CheckLogExists(const std::string& path) {
  std::error_code error;
  fs::path place = path;
  if (path.find('%') != std::string::npos) place = fs::path(path).parent_path();
  if (place.empty() || fs::exists(place, error)) return Status::Ok();
  return Status::NotFound(path + ": no such file or folder");
}

Status ParseTopicChoice(const std::vector<std::string>& assignments, TopicChoice* choice) {
  std::set<std::string> given;
  for (const std::string& assignment : assignments) {
    const std::size_t equals = assignment.find('=');
    const std::string role = assignment.substr(0, equals);
    std::string* slot = role == "camera"        ? &choice->camera
                        : role == "camera_info" ? &choice->camera_info
                        : role == "imu"         ? &choice->imu
                        : role == "gps"         ? &choice->gps
                        : role == "pose"        ? &choice->pose
                        : role == "depth"       ? &choice->depth
                        : role == "right"       ? &choice->right
                                                : nullptr;
    if (equals == std::string::npos || equals + 1 == assignment.size()) {
      return Status::InvalidArgument("--topic " + assignment + ": expected ROLE=TOPIC, e.g. camera=/cam0/image_raw");
    }
    if (slot == nullptr) {
      return Status::InvalidArgument("--topic " + assignment + ": unknown role '" + role +
                                     "' (camera, camera_info, imu, gps, pose, depth, right)");
    }
    if (!given.insert(role).second) return Status::InvalidArgument("--topic: role '" + role + "' given twice");
    *slot = assignment.substr(equals + 1);
  }
  return Status::Ok();
}

Status OpenLog(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source) {
  if (path.find('%') != std::string::npos) return OpenImagePattern(path, options, source);
  if (!PathExists(path)) return Status::NotFound(path + ": no such file or folder");
  if (IsBag(path)) return OpenBag(path, options, source);
  if (fs::is_directory(path)) {
    if (PathExists(path + "/cam0/data.csv") || PathExists(path + "/mav0/cam0/data.csv")) {
      return OpenEuroc(path, source);
    }
    return OpenImageFolder(path, options, source);
  }
  return OpenVideo(path, options, source);
}

}  // namespace patrolmap::io
