#include "kmeans.h"

#include <algorithm>
#include <limits>

namespace patrolmap::vocab {
namespace {

int Nearest(const float* point, const std::vector<float>& centres, int clusters, int dimension, float* distance) {
  int best = 0;
  float best_distance = std::numeric_limits<float>::max();
  for (int c = 0; c < clusters; ++c) {
    const float d = SquaredDistance(point, &centres[static_cast<std::size_t>(c) * dimension], dimension);
    if (d < best_distance) best_distance = d, best = c;
  }
  if (distance != nullptr) *distance = best_distance;
  return best;
}

// k-means++: the first centre uniformly, each next one with probability proportional to D^2.
void SeedPlusPlus(const float* data, int dimension, const std::vector<std::uint32_t>& indices, int k, std::mt19937* rng,
                  std::vector<float>* centres) {
  const std::size_t n = indices.size();
  centres->assign(static_cast<std::size_t>(k) * dimension, 0.0f);
  std::vector<double> distance(n, std::numeric_limits<double>::max());
  std::size_t chosen = std::uniform_int_distribution<std::size_t>(0, n - 1)(*rng);
  for (int c = 0; c < k; ++c) {
    const float* centre = data + static_cast<std::size_t>(indices[chosen]) * dimension;
    std::copy(centre, centre + dimension, centres->begin() + static_cast<std::size_t>(c) * dimension);
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      distance[i] =
          std::min(distance[i], static_cast<double>(SquaredDistance(
                                    data + static_cast<std::size_t>(indices[i]) * dimension, centre, dimension)));
      total += distance[i];
    }
    if (total <= 0.0) {
      chosen = std::uniform_int_distribution<std::size_t>(0, n - 1)(*rng);
      continue;
    }
    double target = std::uniform_real_distribution<double>(0.0, total)(*rng);
    for (chosen = 0; chosen + 1 < n && target >= distance[chosen]; ++chosen) target -= distance[chosen];
  }
}

// Means of the assigned points into fresh storage; an empty cluster keeps its centre.
void UpdateCentres(const float* data, int dimension, const std::vector<std::uint32_t>& indices,
                   const std::vector<int>& assignment, int clusters, std::vector<float>* centres) {
  std::vector<double> sums(static_cast<std::size_t>(clusters) * dimension, 0.0);
  std::vector<int> counts(clusters, 0);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const float* point = data + static_cast<std::size_t>(indices[i]) * dimension;
    double* sum = &sums[static_cast<std::size_t>(assignment[i]) * dimension];
    for (int d = 0; d < dimension; ++d) sum[d] += point[d];
    ++counts[assignment[i]];
  }
  for (int c = 0; c < clusters; ++c) {
    if (counts[c] == 0) continue;
    for (int d = 0; d < dimension; ++d) {
      (*centres)[static_cast<std::size_t>(c) * dimension + d] =
          static_cast<float>(sums[static_cast<std::size_t>(c) * dimension + d] / counts[c]);
    }
  }
}

}  // namespace

float SquaredDistance(const float* a, const float* b, int dimension) {
  float sum = 0.0f;
  for (int d = 0; d < dimension; ++d) {
    const float difference = a[d] - b[d];
    sum += difference * difference;
  }
  return sum;
}

void KMeans(const float* data, int dimension, const std::vector<std::uint32_t>& indices, int k, int max_iterations,
            std::mt19937* rng, Clustering* result) {
  const int n = static_cast<int>(indices.size());
  result->clusters = std::min(k, n);
  result->assignment.assign(n, 0);
  result->iterations = 0;
  if (n <= k) {  // every point is its own cluster
    result->centres.resize(static_cast<std::size_t>(n) * dimension);
    for (int i = 0; i < n; ++i) {
      std::copy(data + static_cast<std::size_t>(indices[i]) * dimension,
                data + static_cast<std::size_t>(indices[i] + 1) * dimension,
                result->centres.begin() + static_cast<std::size_t>(i) * dimension);
      result->assignment[i] = i;
    }
    return;
  }
  SeedPlusPlus(data, dimension, indices, k, rng, &result->centres);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    bool changed = iteration == 0;
    for (int i = 0; i < n; ++i) {
      const int nearest =
          Nearest(data + static_cast<std::size_t>(indices[i]) * dimension, result->centres, k, dimension, nullptr);
      changed |= nearest != result->assignment[i];
      result->assignment[i] = nearest;
    }
    result->iterations = iteration + 1;
    if (!changed) break;
    UpdateCentres(data, dimension, indices, result->assignment, k, &result->centres);
  }
}

}  // namespace patrolmap::vocab
