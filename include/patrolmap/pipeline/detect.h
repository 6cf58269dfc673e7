// Key-location detection over a whole flight log, and its outputs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"
#include "patrolmap/flow/options.h"
#include "patrolmap/io/frame_source.h"

namespace patrolmap::pipeline {

struct DetectionResult {
  std::vector<FlowSample> samples;  // one per processed frame
  std::vector<KeyLocation> key_locations;
  std::int64_t frames_read = 0;           // frames delivered by the source
  std::vector<io::SkippedFrame> skipped;  // unreadable frames that were passed over
  bool derotated = false;                 // flow was de-rotated with the gyro
  double seconds = 0.0;                   // wall time of the run
  flow::FrameTiming timing;               // the frame step and smoothing window used for the log's rate
  int unusable_frames = 0;                // frames due for processing but too small or without an image
};

// What a user should know about a detection run, one sentence each: a log without timestamps, a log
// too short for the smoothing window, a response too flat for any key location, unusable frames. Each
// names the log and says what to change. Empty when all is well.
std::vector<std::string> DetectionWarnings(const io::LogInfo& info, const DetectionResult& result,
                                           const flow::KeyLocationOptions& options);

// Called now and then with (frames read, frames in the log or -1).
using FrameProgress = std::function<void(std::int64_t, std::int64_t)>;

// Runs the flow stage over every frame of `source`. `options` must be valid.
Status RunDetection(io::FrameSource* source, const flow::KeyLocationOptions& options, DetectionResult* result,
                    const FrameProgress& progress = {});

// What the plot can add to the detection: the ground truth where the log has it, and the map's node ids.
struct PlotTruth {
  std::vector<double> times_s;  // true key locations (groundtruth/key_locations.csv) [s]; none: no truth
  std::vector<bool> correct;    // per key location, as `patrolmap eval` judges it (empty: unjudged)
  std::vector<int> node_ids;    // per key location: its id in nodes.csv, -1 when it made no node
                                // (empty: the detector's own numbering)
};

// The plot truth of the key locations of `log` (its groundtruth/ folder; nothing when it has none), judged as
// `patrolmap eval` does.
PlotTruth LoadPlotTruth(const std::string& log, const std::vector<KeyLocation>& key_locations);

// Writes DIR/key_locations.csv, DIR/response.csv and DIR/response.svg (a plot
// like paper 002 Fig. 3: raw and smoothed response, key locations marked).
// Each file is written atomically.
Status WriteDetectionOutputs(const DetectionResult& result, const std::string& folder, const PlotTruth& truth = {});

std::string KeyLocationsCsv(const std::vector<KeyLocation>& key_locations);
std::string ResponseCsv(const std::vector<FlowSample>& samples);
std::string ResponsePlotSvg(const DetectionResult& result, const PlotTruth& truth);

}  // namespace patrolmap::pipeline
