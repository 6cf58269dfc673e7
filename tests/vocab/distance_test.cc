#include "../src/vocab/distance.h"

#include <gtest/gtest.h>

#include "vocab/distance_cases.h"

namespace patrolmap::vocab {
namespace {

using testing_cases::ByteDistanceMismatches;
using testing_cases::FloatDistanceMismatches;

// The AVX2 build of the quantiser's distance gives the portable build's value to the bit (so words do not
// depend on the processor), for SIFT's 128 components and for a dimension with a tail.
TEST(QuantiserDistance, Avx2GivesThePortableValueToTheBit) {
  if (!Avx2Available()) GTEST_SKIP() << "no AVX2 build, or no AVX2 on this processor";
  EXPECT_EQ(FloatDistanceMismatches(kSquaredDistanceTo8BitAvx2), 0);
  EXPECT_EQ(FastestDistance(), kSquaredDistanceTo8BitAvx2);
}

// The matcher's 8-bit distance: the AVX2 build equals the portable one (exact integer sums), from equal rows
// to the largest possible distance.
TEST(MatcherDistance, Avx2GivesThePortableSum) {
  if (!Avx2Available()) GTEST_SKIP() << "no AVX2 build, or no AVX2 on this processor";
  EXPECT_EQ(ByteDistanceMismatches(kSquaredByteDistanceAvx2), 0);
  EXPECT_EQ(FastestByteDistance(), kSquaredByteDistanceAvx2);
}

// On arm64 the NEON builds do the same (scripts/cross_arm64.sh runs these cases under qemu from any machine).
TEST(Distances, NeonGivesThePortableValuesOnArm64) {
  if (kSquaredDistanceTo8BitNeon == nullptr) GTEST_SKIP() << "not an arm64 build";
  EXPECT_EQ(FloatDistanceMismatches(kSquaredDistanceTo8BitNeon), 0);
  EXPECT_EQ(ByteDistanceMismatches(kSquaredByteDistanceNeon), 0);
  EXPECT_EQ(FastestDistance(), kSquaredDistanceTo8BitNeon);
  EXPECT_EQ(FastestByteDistance(), kSquaredByteDistanceNeon);
}

// The portable loops themselves, against sums written out by hand.
TEST(Distances, ThePortableLoopsSumTheSquaredDifferences) {
  const float a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9.5f};
  const std::uint8_t b[9] = {0, 0, 0, 0, 0, 0, 0, 0, 9};
  EXPECT_FLOAT_EQ(SquaredDistanceTo8Bit(a, b, 9), 1 + 4 + 9 + 16 + 25 + 36 + 49 + 64 + 0.25f);
  std::uint8_t x[kDescriptorDimension] = {}, y[kDescriptorDimension] = {};
  x[0] = 3, y[127] = 4;
  EXPECT_EQ(SquaredByteDistance(x, y), 25u);
}

}  // namespace
}  // namespace patrolmap::vocab
