// Test inputs shared by the vocab stage's test files.
#ifndef PATROLMAP_TESTS_VOCAB_FIXTURES_H_
#define PATROLMAP_TESTS_VOCAB_FIXTURES_H_

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap::vocab::testing_fixtures {

// `clusters` well-separated Gaussian blobs of `per_cluster` points in `dimension` dims (values >= 0).
inline cv::Mat Blobs(int clusters, int per_cluster, int dimension, std::uint32_t seed, std::vector<int>* labels) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 2.0f);
  std::uniform_real_distribution<float> centre(20.0f, 235.0f);
  cv::Mat points(clusters * per_cluster, dimension, CV_32F);
  labels->clear();
  for (int c = 0; c < clusters; ++c) {
    std::vector<float> mean(dimension);
    for (float& value : mean) value = centre(rng);
    for (int i = 0; i < per_cluster; ++i) {
      float* row = points.ptr<float>(c * per_cluster + i);
      for (int d = 0; d < dimension; ++d) row[d] = std::max(0.0f, mean[d] + noise(rng));
      labels->push_back(c);
    }
  }
  return points;
}

inline Vocabulary TrainOnBlobs(std::uint32_t seed, std::vector<int>* labels, cv::Mat* points) {
  *points = Blobs(16, 40, 16, 9, labels);
  std::vector<cv::Mat> images;
  for (int i = 0; i < points->rows; i += 40) images.push_back(points->rowRange(i, i + 40));  // one blob per image
  VocabularyOptions options;
  options.branching = 4;
  options.depth = 2;
  options.seed = seed;
  Vocabulary vocabulary;
  EXPECT_TRUE(Vocabulary::Train(images, options, &vocabulary).ok());
  return vocabulary;
}

}  // namespace patrolmap::vocab::testing_fixtures

#endif  // PATROLMAP_TESTS_VOCAB_FIXTURES_H_
