// Test inputs shared by the io stage's test files.
#ifndef PATROLMAP_TESTS_IO_FIXTURES_H_
#define PATROLMAP_TESTS_IO_FIXTURES_H_

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "patrolmap/io/readers.h"
#include "test_util.h"

namespace patrolmap::io::testing_fixtures {

inline cv::Mat TestImage(int value) {
  cv::Mat image(24, 32, CV_8UC1, cv::Scalar(value));
  return image;
}

inline std::vector<Frame> ReadAll(FrameSource* source, Status* end) {
  std::vector<Frame> frames;
  Frame frame;
  while ((*end = source->Next(true, &frame)).ok()) frames.push_back(frame);
  return frames;
}

// A EuRoC log of `count` frames 50 ms apart, images valued 10, 20, 30, ...
inline void MakeEurocLog(const std::string& log, int count) {
  std::filesystem::create_directories(log + "/cam0/data");
  std::string table = "#timestamp [ns],filename\n";
  for (int i = 0; i < count; ++i) {
    const std::string name = std::to_string(1000000000LL + i * 50000000LL) + ".png";
    cv::imwrite(log + "/cam0/data/" + name, TestImage(10 * (i + 1)));
    table += std::to_string(1000000000LL + i * 50000000LL) + "," + name + "\n";
  }
  testing::WriteText(log + "/cam0/data.csv", table);
}

}  // namespace patrolmap::io::testing_fixtures

#endif  // PATROLMAP_TESTS_IO_FIXTURES_H_
