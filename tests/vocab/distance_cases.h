// The cases every accelerated distance kernel is checked on against the portable loop (distance_test.cc on the
// build's own processor, tests/arm64/distance_check.cc under qemu for arm64): how many values differ.
#ifndef PATROLMAP_TESTS_VOCAB_DISTANCE_CASES_H_
#define PATROLMAP_TESTS_VOCAB_DISTANCE_CASES_H_

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "../src/vocab/distance.h"

namespace patrolmap::vocab::testing_cases {

// Quantiser distances for SIFT's 128 components and for dimensions with a tail, over large and small values: the
// number whose bits differ from the portable loop's.
inline int FloatDistanceMismatches(DistanceFunction fast) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(0.0f, 255.0f);
  std::uniform_int_distribution<int> byte(0, 255);
  int mismatches = 0;
  for (const int dimension : {128, 131, 7}) {
    for (int trial = 0; trial < 2000; ++trial) {
      std::vector<float> a(dimension);
      std::vector<std::uint8_t> b(dimension);
      for (float& x : a) x = value(rng) * (trial % 2 == 0 ? 1.0f : 1e-3f);
      for (std::uint8_t& x : b) x = static_cast<std::uint8_t>(byte(rng));
      const float portable = SquaredDistanceTo8Bit(a.data(), b.data(), dimension);
      const float accelerated = fast(a.data(), b.data(), dimension);
      mismatches += std::memcmp(&portable, &accelerated, sizeof(float)) != 0;
    }
  }
  return mismatches;
}

// Matcher distances between random rows, equal rows and the farthest rows: the number that differ.
inline int ByteDistanceMismatches(ByteDistanceFunction fast) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::uint8_t> a(kDescriptorDimension), b(kDescriptorDimension);
  int mismatches = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    for (std::size_t k = 0; k < a.size(); ++k)
      a[k] = static_cast<std::uint8_t>(byte(rng)), b[k] = static_cast<std::uint8_t>(byte(rng));
    mismatches += fast(a.data(), b.data()) != SquaredByteDistance(a.data(), b.data());
  }
  std::fill(a.begin(), a.end(), 0), std::fill(b.begin(), b.end(), 255);
  mismatches += fast(a.data(), b.data()) != 128u * 255u * 255u;
  mismatches += fast(b.data(), a.data()) != 128u * 255u * 255u;
  mismatches += fast(a.data(), a.data()) != 0u;
  return mismatches;
}

}  // namespace patrolmap::vocab::testing_cases

#endif  // PATROLMAP_TESTS_VOCAB_DISTANCE_CASES_H_
