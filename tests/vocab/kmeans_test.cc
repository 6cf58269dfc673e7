#include <atomic>
#include <thread>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "../src/vocab/kmeans.h"
#include "patrolmap/core/checksum.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"
#include "recompute_checksums.h"
#include "test_util.h"
#include "vocab/fixtures.h"

namespace patrolmap::vocab {
namespace {

using testing_fixtures::Blobs;

TEST(KMeans, RecoversSeparatedClustersWithinTheIterationCap) {
  std::vector<int> labels;
  const cv::Mat points = Blobs(4, 50, 8, 3, &labels);
  std::vector<std::uint32_t> indices(points.rows);
  for (int i = 0; i < points.rows; ++i) indices[i] = i;
  std::mt19937 rng(1);
  Clustering clustering;
  KMeans(points.ptr<float>(), 8, indices, 4, 10, &rng, &clustering);
  EXPECT_EQ(clustering.clusters, 4);
  EXPECT_LE(clustering.iterations, 10);
  std::set<std::pair<int, int>> pairs;
  for (int i = 0; i < points.rows; ++i) pairs.insert({labels[i], clustering.assignment[i]});
  EXPECT_EQ(pairs.size(), 4u);  // a one-to-one map between blobs and clusters
}

TEST(KMeans, FewerPointsThanClustersGiveOneClusterEach) {
  const cv::Mat points = (cv::Mat_<float>(2, 2) << 1, 2, 3, 4);
  std::mt19937 rng(1);
  Clustering clustering;
  KMeans(points.ptr<float>(), 2, {0, 1}, 5, 10, &rng, &clustering);
  EXPECT_EQ(clustering.clusters, 2);
  EXPECT_EQ(clustering.assignment, (std::vector<int>{0, 1}));
}

}  // namespace
}  // namespace patrolmap::vocab
