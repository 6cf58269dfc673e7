// Fuzzes the EuRoC reader's tables and YAML files: the input is split at NUL bytes into cam0/data.csv,
// cam0/sensor.yaml, imu0/data.csv, state_groundtruth_estimate0/data.csv, objects0/data.csv,
// depth0/data.csv, gps0/data.csv and meta.yaml of one log; the log is opened, its first frames read (the images are
// missing or tiny) and its change-detection tables read.
#include <cstddef>
#include <cstdint>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include "fuzz_files.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const char* const kFiles[] = {
      "cam0/data.csv",     "cam0/sensor.yaml", "imu0/data.csv", "state_groundtruth_estimate0/data.csv",
      "objects0/data.csv", "depth0/data.csv",  "gps0/data.csv", "meta.yaml"};
  constexpr std::size_t kCount = sizeof(kFiles) / sizeof(kFiles[0]);
  const auto log = patrolmap::fuzz::FreshFolder() / "log";
  const auto pieces = patrolmap::fuzz::SplitInput(data, size, kCount);
  for (std::size_t i = 0; i < kCount; ++i) {
    if (i == 0 || !pieces[i].empty()) patrolmap::fuzz::WriteBytes(log / kFiles[i], pieces[i]);
  }
  std::filesystem::create_directories(log / "cam0/data");
  // The seeds' first two frames exist (a tiny image); the rest are missing.
  for (const char* name : {"0.png", "33333333.png"}) {
    cv::imwrite((log / "cam0/data" / name).string(), cv::Mat(8, 8, CV_8UC1, cv::Scalar(7)));
  }
  std::unique_ptr<patrolmap::io::FrameSource> source;
  if (patrolmap::io::OpenEuroc(log.string(), &source).ok()) {
    patrolmap::Frame frame;
    for (int i = 0; i < 3 && source->Next(true, &frame).ok(); ++i) {
    }
  }
  patrolmap::io::PatrolSensors sensors;
  (void)patrolmap::io::ReadPatrolSensors(log.string(), &sensors);
  return 0;
}
