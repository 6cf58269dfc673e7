// Internal: k-means with k-means++ seeding and a cap on iterations, over rows
// of a contiguous float array picked by index. The input is only read.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace patrolmap::vocab {

struct Clustering {
  int clusters = 0;             // k, or fewer when there are fewer points
  std::vector<float> centres;   // clusters x dimension
  std::vector<int> assignment;  // per point (position in `indices`)
  int iterations = 0;
};

void KMeans(const float* data, int dimension, const std::vector<std::uint32_t>& indices, int k, int max_iterations,
            std::mt19937* rng, Clustering* result);

// Squared Euclidean distance between two rows.
float SquaredDistance(const float* a, const float* b, int dimension);

}  // namespace patrolmap::vocab
