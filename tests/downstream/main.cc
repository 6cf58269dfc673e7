// Uses the installed headers and libraries: checks the flow defaults and runs a few frames.
#include <cstdio>
#include <string>

#include <opencv2/core.hpp>

#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/pipeline/config.h"

int main() {
  patrolmap::pipeline::Config config;
  std::string error;
  if (!config.IsValid(&error) || config.flow.voting.accept != 3) return 1;
  patrolmap::flow::KeyLocationDetector detector(config.flow, {});  // rate unknown: every frame
  patrolmap::flow::DetectorOutput output;
  patrolmap::Frame frame;
  frame.image = cv::Mat(240, 376, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < 3; ++i) {
    frame.index = i;
    frame.timestamp_ns = i * 200000000LL;
    detector.Process(frame, &output);
  }
  std::printf("consumer: %d frames processed\n", detector.processed_frames());
  return detector.processed_frames() == 3 ? 0 : 1;
}
