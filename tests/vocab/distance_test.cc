#include "../src/vocab/distance.h"

#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace patrolmap::vocab {
namespace {

// The AVX2 build of the quantiser's distance gives the portable build's value to the bit (so words do not
// depend on the processor), for SIFT's 128 components and for a dimension with a tail.
TEST(QuantiserDistance, Avx2GivesThePortableValueToTheBit) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (kSquaredDistanceTo8BitAvx2 == nullptr || !__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 here";
#else
  GTEST_SKIP() << "no AVX2 build";
#endif
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

}  // namespace
}  // namespace patrolmap::vocab
