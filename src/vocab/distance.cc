#include "distance.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif
#if defined(__aarch64__)
#include <arm_neon.h>
#endif

namespace patrolmap::vocab {
namespace {

// The eight lanes' partial sums added in a fixed order, then the tail from component `d` on, one at a time: every
// build of the quantiser's distance ends so.
float SumOfLanes(const float (&lanes)[8], const float* a, const std::uint8_t* b, int d, int dimension) {
  float sum = ((lanes[0] + lanes[4]) + (lanes[1] + lanes[5])) + ((lanes[2] + lanes[6]) + (lanes[3] + lanes[7]));
  for (; d < dimension; ++d) {
    const float difference = a[d] - static_cast<float>(b[d]);
    sum += difference * difference;
  }
  return sum;
}

}  // namespace

// Eight independent partial sums, so the compiler keeps them in vector registers (a single running float sum
// is a dependency chain it may not reorder); the tail, when the dimension is not a multiple of 8, runs alone.
float SquaredDistanceTo8Bit(const float* a, const std::uint8_t* b, int dimension) {
  constexpr int kLanes = 8;
  float lanes[kLanes] = {};
  int d = 0;
  for (; d + kLanes <= dimension; d += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const float difference = a[d + l] - static_cast<float>(b[d + l]);
      lanes[l] += difference * difference;
    }
  }
  return SumOfLanes(lanes, a, b, d, dimension);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// The same eight lanes as one AVX register: each lane subtracts, squares and adds in the same order as above,
// and the lanes and the tail are summed as above, so the distances are the same to the bit. (AVX2 alone does
// not fuse the multiply and the add.) GCC does not find this form itself: it keeps the lanes in pairs.
namespace {

__attribute__((target("avx2"))) float SquaredDistanceTo8BitAvx2(const float* a, const std::uint8_t* b, int dimension) {
  __m256 sums = _mm256_setzero_ps();
  int d = 0;
  for (; d + 8 <= dimension; d += 8) {
    const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(b + d));
    const __m256 difference = _mm256_sub_ps(_mm256_loadu_ps(a + d), _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes)));
    sums = _mm256_add_ps(sums, _mm256_mul_ps(difference, difference));
  }
  float lanes[8];
  _mm256_storeu_ps(lanes, sums);
  return SumOfLanes(lanes, a, b, d, dimension);
}

}  // namespace

const DistanceFunction kSquaredDistanceTo8BitAvx2 = SquaredDistanceTo8BitAvx2;
#else
const DistanceFunction kSquaredDistanceTo8BitAvx2 = nullptr;
#endif

#if defined(__aarch64__)
namespace {

// The same eight lanes as two NEON registers (lanes 0-3 and 4-7): each lane subtracts, squares and adds in the same
// order as the portable loop, with the multiply and the add apart (this file is built with -ffp-contract=off,
// so the portable loop does not fuse them either), and the lanes and the tail are summed as there: the same value
// to the bit.
float SquaredDistanceTo8BitNeon(const float* a, const std::uint8_t* b, int dimension) {
  float32x4_t low = vdupq_n_f32(0.0f), high = vdupq_n_f32(0.0f);
  int d = 0;
  for (; d + 8 <= dimension; d += 8) {
    const uint16x8_t bytes = vmovl_u8(vld1_u8(b + d));
    const float32x4_t b_low = vcvtq_f32_u32(vmovl_u16(vget_low_u16(bytes)));
    const float32x4_t b_high = vcvtq_f32_u32(vmovl_u16(vget_high_u16(bytes)));
    const float32x4_t difference_low = vsubq_f32(vld1q_f32(a + d), b_low);
    const float32x4_t difference_high = vsubq_f32(vld1q_f32(a + d + 4), b_high);
    low = vaddq_f32(low, vmulq_f32(difference_low, difference_low));
    high = vaddq_f32(high, vmulq_f32(difference_high, difference_high));
  }
  float lanes[8];
  vst1q_f32(lanes, low);
  vst1q_f32(lanes + 4, high);
  return SumOfLanes(lanes, a, b, d, dimension);
}

}  // namespace

const DistanceFunction kSquaredDistanceTo8BitNeon = SquaredDistanceTo8BitNeon;
#else
const DistanceFunction kSquaredDistanceTo8BitNeon = nullptr;
#endif

bool Avx2Available() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool available = __builtin_cpu_supports("avx2");
  return available;
#else
  return false;
#endif
}

DistanceFunction FastestDistance() {
  if (kSquaredDistanceTo8BitNeon != nullptr) return kSquaredDistanceTo8BitNeon;  // every arm64 processor has NEON
  return Avx2Available() ? kSquaredDistanceTo8BitAvx2 : SquaredDistanceTo8Bit;
}

std::uint32_t SquaredByteDistance(const std::uint8_t* a, const std::uint8_t* b) {
  std::uint32_t sum = 0;
  for (int k = 0; k < kDescriptorDimension; ++k) {
    const int difference = static_cast<int>(a[k]) - static_cast<int>(b[k]);
    sum += static_cast<std::uint32_t>(difference * difference);
  }
  return sum;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
namespace {

// The same sum, sixteen components at a time: widened to 16 bits, subtracted, and squared and added in pairs
// into 32-bit lanes (vpmaddwd). Integer sums are exact, so it equals the loop above.
__attribute__((target("avx2"))) std::uint32_t SquaredByteDistanceAvx2(const std::uint8_t* a, const std::uint8_t* b) {
  __m256i sums = _mm256_setzero_si256();
  for (int k = 0; k < kDescriptorDimension; k += 16) {
    const __m256i x = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k)));
    const __m256i y = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k)));
    const __m256i difference = _mm256_sub_epi16(x, y);
    sums = _mm256_add_epi32(sums, _mm256_madd_epi16(difference, difference));
  }
  const __m128i half = _mm_add_epi32(_mm256_castsi256_si128(sums), _mm256_extracti128_si256(sums, 1));
  const __m128i quarter = _mm_add_epi32(half, _mm_shuffle_epi32(half, _MM_SHUFFLE(1, 0, 3, 2)));
  const __m128i total = _mm_add_epi32(quarter, _mm_shuffle_epi32(quarter, _MM_SHUFFLE(2, 3, 0, 1)));
  return static_cast<std::uint32_t>(_mm_cvtsi128_si32(total));
}

}  // namespace

const ByteDistanceFunction kSquaredByteDistanceAvx2 = SquaredByteDistanceAvx2;
#else
const ByteDistanceFunction kSquaredByteDistanceAvx2 = nullptr;
#endif

#if defined(__aarch64__)
namespace {

// The same sum, sixteen components at a time: the differences widened to 16 bits, squared and summed into 32-bit
// lanes (smull/smlal). Integer sums are exact, so it equals the portable loop.
std::uint32_t SquaredByteDistanceNeon(const std::uint8_t* a, const std::uint8_t* b) {
  int32x4_t sums = vdupq_n_s32(0);
  for (int k = 0; k < kDescriptorDimension; k += 16) {
    const uint8x16_t x = vld1q_u8(a + k), y = vld1q_u8(b + k);
    const int16x8_t low = vreinterpretq_s16_u16(vsubl_u8(vget_low_u8(x), vget_low_u8(y)));
    const int16x8_t high = vreinterpretq_s16_u16(vsubl_u8(vget_high_u8(x), vget_high_u8(y)));
    sums = vmlal_s16(sums, vget_low_s16(low), vget_low_s16(low));
    sums = vmlal_s16(sums, vget_high_s16(low), vget_high_s16(low));
    sums = vmlal_s16(sums, vget_low_s16(high), vget_low_s16(high));
    sums = vmlal_s16(sums, vget_high_s16(high), vget_high_s16(high));
  }
  return static_cast<std::uint32_t>(vaddvq_s32(sums));
}

}  // namespace

const ByteDistanceFunction kSquaredByteDistanceNeon = SquaredByteDistanceNeon;
#else
const ByteDistanceFunction kSquaredByteDistanceNeon = nullptr;
#endif

ByteDistanceFunction FastestByteDistance() {
  if (kSquaredByteDistanceNeon != nullptr) return kSquaredByteDistanceNeon;
  return Avx2Available() ? kSquaredByteDistanceAvx2 : SquaredByteDistance;
}

}  // namespace patrolmap::vocab
