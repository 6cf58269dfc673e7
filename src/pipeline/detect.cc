#include "patrolmap/pipeline/detect.h"

#include <chrono>

#include "patrolmap/core/files.h"
#include "patrolmap/flow/key_location_detector.h"

namespace patrolmap::pipeline {

Status RunDetection(io::FrameSource* source, const flow::KeyLocationOptions& options, DetectionResult* result,
                    const FrameProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const io::LogInfo& info = source->info();
  flow::KeyLocationDetector detector(options, {info.camera, info.camera_from_imu});
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
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result->samples.empty()) return Status::DataLoss(info.path + ": no frame could be read");
  return Status::Ok();
}

Status WriteDetectionOutputs(const DetectionResult& result, const std::string& folder, const PlotTruth& truth) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/key_locations.csv", KeyLocationsCsv(result.key_locations)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/response.csv", ResponseCsv(result.samples)));
  return WriteFileAtomically(folder + "/response.svg", ResponsePlotSvg(result, truth));
}

}  // namespace patrolmap::pipeline
