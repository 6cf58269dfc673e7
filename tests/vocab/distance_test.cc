#include "../src/vocab/distance.h"

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace patrolmap::vocab {
namespace {

// The AVX2 build of the quantiser's distance gives the portable build's value to the bit (so words do not
// depend on the processor), for SIFT's 128 components and for a dimension with a tail.
TEST(QuantiserDistance, Avx2GivesThePortableValueToTheBit) {
  if (!Avx2Available()) GTEST_SKIP() << "no AVX2 build, or no AVX2 on this processor";
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(0.0f, 255.0f);
  std::uniform_int_distribution<int> byte(0, 255);
  for (const int dimension : {128, 131, 7}) {
    for (int trial = 0; trial < 2000; ++trial) {
      std::vector<float> a(dimension);
      std::vector<std::uint8_t> b(dimension);
      for (float& x : a) x = value(rng) * (trial % 2 == 0 ? 1.0f : 1e-3f);
      for (std::uint8_t& x : b) x = static_cast<std::uint8_t>(byte(rng));
      const float portable = SquaredDistanceTo8Bit(a.data(), b.data(), dimension);
      const float avx2 = kSquaredDistanceTo8BitAvx2(a.data(), b.data(), dimension);
      ASSERT_EQ(std::memcmp(&portable, &avx2, sizeof(float)), 0) << dimension << ": " << portable << " vs " << avx2;
    }
  }
  EXPECT_EQ(FastestDistance(), kSquaredDistanceTo8BitAvx2);
}

// The matcher's 8-bit distance: the AVX2 build equals the portable one (exact integer sums), from equal rows
// to the largest possible distance.
TEST(MatcherDistance, Avx2GivesThePortableSum) {
  if (!Avx2Available()) GTEST_SKIP() << "no AVX2 build, or no AVX2 on this processor";
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::uint8_t> a(kDescriptorDimension), b(kDescriptorDimension);
  for (int trial = 0; trial < 2000; ++trial) {
    for (std::size_t k = 0; k < a.size(); ++k)
      a[k] = static_cast<std::uint8_t>(byte(rng)), b[k] = static_cast<std::uint8_t>(byte(rng));
    ASSERT_EQ(kSquaredByteDistanceAvx2(a.data(), b.data()), SquaredByteDistance(a.data(), b.data()));
  }
  std::fill(a.begin(), a.end(), 0), std::fill(b.begin(), b.end(), 255);
  EXPECT_EQ(SquaredByteDistance(a.data(), b.data()), 128u * 255u * 255u);
  EXPECT_EQ(kSquaredByteDistanceAvx2(a.data(), b.data()), 128u * 255u * 255u);
  EXPECT_EQ(kSquaredByteDistanceAvx2(a.data(), a.data()), 0u);
  EXPECT_EQ(FastestByteDistance(), kSquaredByteDistanceAvx2);
}

}  // namespace
}  // namespace patrolmap::vocab
