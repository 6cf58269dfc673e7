// Image-folder, printf-pattern and video readers, and the choice between readers.
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "image_list_source.h"
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
  if (options.frame_rate_hz > 0.0) return Status::Ok();
  return Status::InvalidArgument("frame rate must be positive, is " +
                                 std::to_string(options.frame_rate_hz));
}

std::vector<ImageEntry> TimestampAtRate(const std::vector<std::string>& paths, double rate_hz) {
  std::vector<ImageEntry> entries(paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i) {
    entries[i] = {SecondsToNs(static_cast<double>(i) / rate_hz), paths[i]};
  }
  return entries;
}

std::string FormatPattern(const std::string& pattern, int index) {
  std::vector<char> buffer(pattern.size() + 32);
  std::snprintf(buffer.data(), buffer.size(), pattern.c_str(), index);
  return buffer.data();
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
    if (!capture_.grab()) return Status::EndOfStream();
    frame->index = next_index_++;
    frame->timestamp_ns = SecondsToNs(static_cast<double>(frame->index) / info_.frame_rate_hz);
    if (live_) {
      const auto now = std::chrono::steady_clock::now();
      if (frame->index == 0) start_ = now;
      frame->timestamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_).count();
    }
    if (decode_image) {
      capture_.retrieve(buffer_);
      if (buffer_.channels() == 1) {
        buffer_.copyTo(frame->image);
      } else {
        cv::cvtColor(buffer_, frame->image, cv::COLOR_BGR2GRAY);
      }
    }
    return Status::Ok();
  }
  const LogInfo& info() const override { return info_; }

 private:
  LogInfo info_;
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
  info.flight_id = fs::path(path).lexically_normal().filename().string();
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
    if (item.is_regular_file() && IsImageFile(item.path())) names.push_back(item.path().filename());
  }
  if (error) return Status::IoError(folder + ": cannot list: " + error.message());
  if (names.empty()) return Status::DataLoss(folder + ": folder holds no images (.png, .jpg, ...)");
  NaturalSort(&names);
  for (std::string& name : names) name = (fs::path(folder) / name).string();
  *source = std::make_unique<ImageListSource>(MakeInfo(folder, "image-folder", options.frame_rate_hz),
                                              TimestampAtRate(names, options.frame_rate_hz));
  return Status::Ok();
}

Status OpenImagePattern(const std::string& pattern, const ImageFolderOptions& options,
                        std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  const int first = fs::exists(FormatPattern(pattern, 0)) ? 0 : 1;
  std::vector<std::string> paths;
  for (int index = first; fs::exists(FormatPattern(pattern, index)); ++index) {
    paths.push_back(FormatPattern(pattern, index));
  }
  if (paths.empty()) {
    return Status::NotFound(pattern + ": no file matches the pattern (tried " +
                            FormatPattern(pattern, 0) + " and " + FormatPattern(pattern, 1) + ")");
  }
  *source = std::make_unique<ImageListSource>(MakeInfo(pattern, "image-pattern", options.frame_rate_hz),
                                              TimestampAtRate(paths, options.frame_rate_hz));
  return Status::Ok();
}

Status OpenVideo(const std::string& path, const ImageFolderOptions& options,
                 std::unique_ptr<FrameSource>* source) {
  PATROLMAP_RETURN_IF_ERROR(CheckFrameRate(options));
  if (!fs::is_regular_file(path)) return Status::NotFound(path + ": no such file");
  cv::VideoCapture capture(path);
  if (!capture.isOpened()) return Status::DataLoss(path + ": not a video OpenCV can decode");
  const double reported_rate = capture.get(cv::CAP_PROP_FPS);
  LogInfo info = MakeInfo(path, "video", reported_rate > 0.0 ? reported_rate : options.frame_rate_hz);
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
  LogInfo info = MakeInfo("camera" + std::to_string(device), "camera", reported_rate > 0.0 ? reported_rate : options.frame_rate_hz);
  *source = std::make_unique<VideoSource>(std::move(info), std::move(capture), true);
  return Status::Ok();
}

Status OpenLog(const std::string& path, const ImageFolderOptions& options,
               std::unique_ptr<FrameSource>* source) {
  if (path.find('%') != std::string::npos) return OpenImagePattern(path, options, source);
  if (!fs::exists(path)) return Status::NotFound(path + ": no such file or folder");
  if (fs::is_directory(path)) {
    if (fs::exists(path + "/cam0/data.csv") || fs::exists(path + "/mav0/cam0/data.csv")) {
      return OpenEuroc(path, source);
    }
    return OpenImageFolder(path, options, source);
  }
  return OpenVideo(path, options, source);
}

}  // namespace patrolmap::io
