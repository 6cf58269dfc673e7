#include "patrolmap/pipeline/route_strip.h"

#include <algorithm>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace patrolmap::pipeline {

RouteStrip::RouteStrip(const change::RouteFrameOptions& options)
    : options_(options),
      gate_(options.interval_s > 0.0 ? 1.0 / options.interval_s : 1.0),
      encode_parameters_{cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality} {}

bool RouteStrip::Due(TimestampNs timestamp_ns) {
  if (options_.interval_s <= 0.0 || !gate_.Due(timestamp_ns)) return false;
  gate_.Take(timestamp_ns);
  return true;
}

bool RouteStrip::DueSoon(TimestampNs last_ns, TimestampNs spacing_ns) const {
  return options_.interval_s > 0.0 && gate_.Due(last_ns + 2 * std::max<TimestampNs>(spacing_ns, 0));
}

void RouteStrip::Scale(const cv::Mat& image, cv::Mat* scaled) const {
  if (image.cols <= options_.max_width) {
    image.copyTo(*scaled);
    return;
  }
  const double scale = static_cast<double>(options_.max_width) / image.cols;
  cv::resize(image, *scaled, cv::Size(options_.max_width, std::max(1, cvRound(image.rows * scale))), 0, 0,
             cv::INTER_AREA);
}

void RouteStrip::Add(RouteFrame frame, const cv::Mat& image, bool key_frame) {
  const std::size_t budget = static_cast<std::size_t>(options_.memory_mb * 1024.0 * 1024.0);
  const long long candidate = key_frame ? -1 : candidates_++;
  if (candidate >= 0 && candidate % (1LL << thinnings_) != 0) return;  // between the kept ones since thinning
  if (image.empty() || !cv::imencode(".jpg", image, frame.jpeg, encode_parameters_)) return;
  while (bytes_ + frame.jpeg.size() > budget &&
         std::any_of(candidate_.begin(), candidate_.end(), [](long long c) { return c > 0; })) {
    Thin();
    if (candidate >= 0 && candidate % (1LL << thinnings_) != 0) return;
  }
  if (bytes_ + frame.jpeg.size() > budget) {
    ++dropped_;
    return;
  }
  bytes_ += frame.jpeg.size();
  frames_.push_back(std::move(frame));
  candidate_.push_back(candidate);
}

// Drops every other interval frame (those whose number is not a multiple of the doubled interval).
void RouteStrip::Thin() {
  ++thinnings_;
  const long long step = 1LL << thinnings_;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    if (candidate_[i] >= 0 && candidate_[i] % step != 0) {
      bytes_ -= frames_[i].jpeg.size();
      continue;
    }
    if (kept != i) {
      frames_[kept] = std::move(frames_[i]);
      candidate_[kept] = candidate_[i];
    }
    ++kept;
  }
  frames_.resize(kept);
  candidate_.resize(kept);
}

std::vector<RouteFrame> RouteStrip::Take() {
  std::stable_sort(frames_.begin(), frames_.end(),
                   [](const RouteFrame& a, const RouteFrame& b) { return a.timestamp_ns < b.timestamp_ns; });
  candidate_.clear();
  bytes_ = 0;
  return std::move(frames_);
}

}  // namespace patrolmap::pipeline
