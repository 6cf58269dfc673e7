#include "patrolmap/flow/key_location_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "patrolmap/core/status.h"

namespace patrolmap::flow {

double SceneFlowResponse(const std::vector<PolarVector>& vectors, const std::vector<std::uint8_t>& accepted,
                         ResponseQuantity quantity, int image_width) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < vectors.size(); ++i) {
    if (!accepted[i]) continue;
    sum += quantity == ResponseQuantity::kLength ? vectors[i].length : vectors[i].r;
    ++count;
  }
  if (count == 0) return std::numeric_limits<double>::quiet_NaN();
  return sum / count / image_width;
}

namespace {

bool CheckedOptions(const KeyLocationOptions& options) {
  std::string error;
  const bool valid = options.IsValid(&error);
  if (!valid) std::fprintf(stderr, "invalid KeyLocationOptions: %s\n", error.c_str());
  return valid;
}

}  // namespace

KeyLocationDetector::KeyLocationDetector(const KeyLocationOptions& options, const CameraContext& context)
    : options_(options),
      context_(context),
      timing_(ResolveFrameTiming(options, context.frame_rate_hz)),
      tracker_(options.edges, options.tracker),
      smoother_(timing_.window, options.smoothing.mode),
      extrema_(options.extrema) {
  PATROLMAP_CHECK(CheckedOptions(options));
  derotate_ = options.response.derotate_with_imu && context.camera && context.camera_from_imu;
}

void KeyLocationDetector::Process(const Frame& frame, DetectorOutput* output) {
  pending_imu_.insert(pending_imu_.end(), frame.imu.begin(), frame.imu.end());
  if (frames_until_next_ > 0) {
    --frames_until_next_;
    return;
  }
  if (Usable(frame.image)) {
    ProcessSelected(frame, output);
  } else {
    ++unusable_frames_;
  }
  frames_until_next_ = timing_.step - 1;
}

bool KeyLocationDetector::Usable(const cv::Mat& image) const {
  const double scale = std::min(options_.frames.scale, 1.0);
  return !image.empty() && image.type() == CV_8UC1 && image.cols * scale >= kMinProcessedSide &&
         image.rows * scale >= kMinProcessedSide && (last_image_.empty() || image.size() == last_size_);
}

const cv::Mat& KeyLocationDetector::Downscale(const cv::Mat& image) {
  last_size_ = image.size();
  if (options_.frames.scale >= 1.0) return image;
  cv::resize(image, small_, cv::Size(), options_.frames.scale, options_.frames.scale, cv::INTER_AREA);
  return small_;
}

void KeyLocationDetector::ProcessSelected(const Frame& frame, DetectorOutput* output) {
  const cv::Mat& image = Downscale(frame.image);
  last_image_ = image;
  if (!voter_) voter_.emplace(options_.voting, image.cols, image.rows);
  tracker_.Track(image, &vectors_);
  if (derotate_ && previous_processed_ns_) Derotate(frame.timestamp_ns, image.cols);
  polar_.resize(vectors_.size());
  std::transform(vectors_.begin(), vectors_.end(), polar_.begin(), ToPolar);
  FlowSample sample;
  sample.timestamp_ns = frame.timestamp_ns;
  sample.frame_index = frame.index;
  sample.tracked_vectors = static_cast<int>(vectors_.size());
  sample.accepted_vectors = voter_->Vote(polar_, &accepted_);
  sample.raw_response = ResponseOf(frame, image.cols);
  previous_processed_ns_ = frame.timestamp_ns;
  pending_imu_.clear();
  ++processed_frames_;
  Emit(sample, output);
}

void KeyLocationDetector::Derotate(TimestampNs timestamp_ns, int image_width) {
  const double scale = static_cast<double>(image_width) / context_.camera->width;
  const Eigen::Matrix3d rotation =
      IntegrateGyro(pending_imu_, *previous_processed_ns_, timestamp_ns, *context_.camera_from_imu);
  DerotateFlow(context_.camera->Scaled(scale), rotation, &vectors_);
}

// Equation 3 in the documented unit: lengths become a rate over the time since
// the previous processed frame; optionally scaled to the reference speed.
double KeyLocationDetector::ResponseOf(const Frame& frame, int image_width) const {
  double response = SceneFlowResponse(polar_, accepted_, options_.response.quantity, image_width);
  if (options_.response.quantity == ResponseQuantity::kLength) {
    const double interval_s = previous_processed_ns_ ? NsToSeconds(frame.timestamp_ns - *previous_processed_ns_) : 0.0;
    response = interval_s > 0.0 ? response / interval_s : std::numeric_limits<double>::quiet_NaN();
  }
  if (!options_.response.normalise_by_speed || !frame.speed_mps) return response;
  const double speed = std::max(*frame.speed_mps, options_.response.min_speed_mps);
  return response * options_.response.reference_speed_mps / speed;
}

void KeyLocationDetector::Emit(const FlowSample& sample, DetectorOutput* output) {
  released_.clear();
  smoother_.Add(sample, &released_);
  DetectExtrema(output);
}

void KeyLocationDetector::Finish(DetectorOutput* output) {
  released_.clear();
  smoother_.Finish(&released_);
  DetectExtrema(output);
}

void KeyLocationDetector::DetectExtrema(DetectorOutput* output) {
  for (const FlowSample& released : released_) {
    extrema_.Add(released, &output->key_locations);
    output->samples.push_back(released);
  }
}

}  // namespace patrolmap::flow
