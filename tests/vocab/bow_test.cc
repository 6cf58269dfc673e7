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

TEST(BowVector, IdenticalScoresOneDisjointZero) {
  const std::vector<float> idf = {1.0f, 2.0f, 0.5f, 1.0f, 0.0f};
  BowVector a, b, c;
  MakeBowVector({0, 1, 1, 2}, idf.data(), &a);
  MakeBowVector({0, 1, 1, 2}, idf.data(), &b);
  MakeBowVector({3, 4}, idf.data(), &c);  // word 4 has idf 0 and is dropped
  EXPECT_NEAR(L1Score(a, b), 1.0, 1e-6);
  EXPECT_NEAR(L1Score(a, c), 0.0, 1e-12);
  ASSERT_EQ(c.words, (std::vector<WordId>{3}));
  float sum = 0.0f;
  for (float weight : a.weights) sum += weight;
  EXPECT_NEAR(sum, 1.0f, 1e-6);
  EXPECT_NEAR(a.weights[1], 4.0 / 5.5, 1e-6);  // tf 2 x idf 2 of 1 + 4 + 0.5
  BowVector d;
  MakeBowVector({0, 1}, idf.data(), &d);
  EXPECT_NEAR(L1Score(a, d), L1Score(d, a), 1e-12);
  EXPECT_GT(L1Score(a, d), 0.3);
  EXPECT_LT(L1Score(a, d), 1.0);
}

}  // namespace
}  // namespace patrolmap::vocab
