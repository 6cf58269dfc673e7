// Internal: the squared Euclidean distances of the descriptor inner loops, each built portable, with AVX2 (x86-64)
// and with NEON (arm64), all giving the same value to the bit, so results do not depend on the processor.
// - From a float descriptor to an 8-bit vocabulary centre: quantisation.
// - Between two 8-bit descriptors of 128 components, summed exactly in integers: matching (FindNearestTwo).
#pragma once

#include <cstdint>

#include "patrolmap/vocab/descriptors.h"

namespace patrolmap::vocab {

using DistanceFunction = float (*)(const float* a, const std::uint8_t* b, int dimension);

float SquaredDistanceTo8Bit(const float* a, const std::uint8_t* b, int dimension);
// The same with AVX2 instructions; nullptr where this build has none (not x86-64, or a compiler without
// GCC's target attribute). Call it only where the processor has AVX2.
extern const DistanceFunction kSquaredDistanceTo8BitAvx2;
// The same with NEON instructions; nullptr where this build is not arm64 (where every processor has NEON).
extern const DistanceFunction kSquaredDistanceTo8BitNeon;

// Whether this build has the AVX2 loops and this processor runs them (asked once).
bool Avx2Available();

// The fastest of those this build has and this processor runs.
DistanceFunction FastestDistance();

using ByteDistanceFunction = std::uint32_t (*)(const std::uint8_t* a, const std::uint8_t* b);

std::uint32_t SquaredByteDistance(const std::uint8_t* a, const std::uint8_t* b);
extern const ByteDistanceFunction kSquaredByteDistanceAvx2;  // nullptr as above
extern const ByteDistanceFunction kSquaredByteDistanceNeon;  // nullptr as above
ByteDistanceFunction FastestByteDistance();

}  // namespace patrolmap::vocab
