// Test inputs shared by the flow stage's test files.
#ifndef PATROLMAP_TESTS_FLOW_FIXTURES_H_
#define PATROLMAP_TESTS_FLOW_FIXTURES_H_

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace patrolmap::flow::testing_fixtures {

// Smooth random texture the size of a simulated key frame (376x240), with strong edges everywhere.
inline cv::Mat Texture(int seed) {
  cv::Mat image(240, 376, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
  return image;
}

}  // namespace patrolmap::flow::testing_fixtures

#endif  // PATROLMAP_TESTS_FLOW_FIXTURES_H_
