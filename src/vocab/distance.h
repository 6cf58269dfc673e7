// Internal: the squared Euclidean distance from a float descriptor to an 8-bit vocabulary centre, the inner
// loop of quantisation. Two builds of it, portable and AVX2, give the same value to the bit, so a vocabulary
// gives the same words on any x86-64 processor.
#pragma once

#include <cstdint>

namespace patrolmap::vocab {

using DistanceFunction = float (*)(const float* a, const std::uint8_t* b, int dimension);

float SquaredDistanceTo8Bit(const float* a, const std::uint8_t* b, int dimension);
// The same with AVX2 instructions; nullptr where this build has none (not x86-64, or a compiler without
// GCC's target attribute). Call it only where the processor has AVX2.
extern const DistanceFunction kSquaredDistanceTo8BitAvx2;

// The fastest of the two this processor runs, chosen once.
DistanceFunction FastestDistance();

}  // namespace patrolmap::vocab
