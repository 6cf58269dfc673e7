#include "patrolmap/pipeline/detect.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "patrolmap/core/files.h"
#include "patrolmap/flow/key_location_detector.h"

namespace patrolmap::pipeline {

Status RunDetection(io::FrameSource* source, const flow::KeyLocationOptions& options, DetectionResult* result,
                    const FrameProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const io::LogInfo& info = source->info();
  flow::KeyLocationDetector detector(options, {info.camera, info.camera_from_imu, info.frame_rate_hz});
  flow::DetectorOutput output;
  Frame frame;
  Status status;
  *result = DetectionResult();
  while ((status = source->Next(detector.NeedsImage(), &frame)).ok()) {
    detector.Process(frame, &output);
    ++result->frames_read;
    if (progress && result->frames_read % 50 == 0) progress(result->frames_read, info.frame_count);
  }
  if (!status.end_of_stream()) return status;
  detector.Finish(&output);
  if (progress) progress(result->frames_read, info.frame_count);
  result->samples = std::move(output.samples);
  result->key_locations = std::move(output.key_locations);
  result->skipped = source->skipped();
  result->derotated = detector.derotating();
  result->timing = detector.timing();
  result->unusable_frames = detector.unusable_frames();
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result->samples.empty()) return Status::DataLoss(info.path + ": no frame could be read");
  return Status::Ok();
}

namespace {

// Smallest and largest smoothed response of the run (NaN samples left out); {0, 0} when none.
std::pair<double, double> SmoothedRange(const std::vector<FlowSample>& samples) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const FlowSample& sample : samples) {
    if (std::isnan(sample.smoothed_response)) continue;
    low = std::min(low, sample.smoothed_response);
    high = std::max(high, sample.smoothed_response);
  }
  return low <= high ? std::make_pair(low, high) : std::make_pair(0.0, 0.0);
}

// Three significant digits, for a message.
std::string Short(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", value);
  return text;
}

// Why a run found no key location, and what to change.
std::string WhyNoKeyLocation(const io::LogInfo& info, const DetectionResult& result,
                             const flow::KeyLocationOptions& options, double duration_s) {
  const std::string prefix = info.path + ": no key location: ";
  if (duration_s < 2.0 * options.smoothing.window_s) {
    return prefix + "the log is too short for the smoothing window (flow.smoothing.window_s)";
  }
  int accepted = 0;
  for (const FlowSample& sample : result.samples) accepted += sample.accepted_vectors > 0;
  if (accepted == 0) {
    return prefix +
           "no flow vector was accepted in any frame (too few edges, or the camera does not move); "
           "check flow.edges.canny_low/canny_high and that the log is a moving camera";
  }
  const auto [low, high] = SmoothedRange(result.samples);
  if (high - low < options.extrema.min_change) {
    return prefix + "the smoothed response varies by " + Short(high - low) +
           ", less than flow.extrema.min_change = " + Short(options.extrema.min_change) +
           " (a camera that hardly moves, or a uniform scene); lower "
           "flow.extrema.min_change to about a third of that range";
  }
  return prefix +
         "no peak or valley of the smoothed response was confirmed (the response must turn back by "
         "flow.extrema.min_change = " +
         Short(options.extrema.min_change) +
         " after it, at least "
         "flow.extrema.min_time_s = " +
         Short(options.extrema.min_time_s) + " s after the previous one)";
}

}  // namespace

std::vector<std::string> DetectionWarnings(const io::LogInfo& info, const DetectionResult& result,
                                           const flow::KeyLocationOptions& options) {
  std::vector<std::string> warnings;
  if (!info.timed) {
    warnings.push_back(info.path + ": the log has no timestamps, so its frames are taken as " +
                       Short(info.frame_rate_hz) +
                       " Hz; give --fps (input.frame_rate_hz) for the real rate, or, for a collection of "
                       "photographs rather than a video's frames, map --every-frame (each image a node)");
  }
  const double duration_s = result.samples.size() < 2
                                ? 0.0
                                : NsToSeconds(result.samples.back().timestamp_ns - result.samples.front().timestamp_ns);
  if (duration_s < 2.0 * options.smoothing.window_s) {
    warnings.push_back(info.path + ": the log lasts " + Short(duration_s) +
                       " s, less than twice the smoothing "
                       "window (flow.smoothing.window_s = " +
                       Short(options.smoothing.window_s) + " s, " + std::to_string(result.timing.window) +
                       " processed frames), which flattens the response; "
                       "for short logs lower flow.smoothing.window_s to about a quarter of the log (--set "
                       "flow.smoothing.window_s=" +
                       Short(std::max(0.1, duration_s / 4.0)) + ")");
  }
  if (result.unusable_frames > 0) {
    warnings.push_back(info.path + ": " + std::to_string(result.unusable_frames) + " frames were too small (under " +
                       std::to_string(flow::kMinProcessedSide) +
                       " pixels a side at flow.frames.scale), of another size "
                       "than the frames before, or not grey, and were skipped");
  }
  if (result.key_locations.empty() && !result.samples.empty()) {
    warnings.push_back(WhyNoKeyLocation(info, result, options, duration_s));
  }
  return warnings;
}

Status WriteDetectionOutputs(const DetectionResult& result, const std::string& folder, const PlotTruth& truth) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/key_locations.csv", KeyLocationsCsv(result.key_locations)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/response.csv", ResponseCsv(result.samples)));
  return WriteFileAtomically(folder + "/response.svg", ResponsePlotSvg(result, truth));
}

}  // namespace patrolmap::pipeline
