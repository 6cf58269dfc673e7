// The vocabulary's NEON distance kernels against the portable loops, built for arm64 and run under qemu by
// scripts/cross_arm64.sh (the suite's GoogleTest programs are not cross-built). Exit 0 when every value agrees.
#include <chrono>
#include <cstdio>
#include <vector>

#include "vocab/distance_cases.h"

namespace {

// Seconds for `calls` quantiser distances of 128 components with `distance`.
double Seconds(patrolmap::vocab::DistanceFunction distance, int calls) {
  std::vector<float> a(128, 17.5f);
  std::vector<std::uint8_t> b(128, 3);
  volatile float sink = 0.0f;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < calls; ++i) {
    a[i % 128] += 1.0f;
    sink = sink + distance(a.data(), b.data(), 128);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main() {
  using namespace patrolmap::vocab;
  if (kSquaredDistanceTo8BitNeon == nullptr || kSquaredByteDistanceNeon == nullptr) {
    std::printf("FAIL: not an arm64 build (no NEON kernels)\n");
    return 1;
  }
  const int quantiser = testing_cases::FloatDistanceMismatches(kSquaredDistanceTo8BitNeon);
  const int matcher = testing_cases::ByteDistanceMismatches(kSquaredByteDistanceNeon);
  const bool fastest =
      FastestDistance() == kSquaredDistanceTo8BitNeon && FastestByteDistance() == kSquaredByteDistanceNeon;
  std::printf("arm64 NEON kernels: quantiser %d of 6000 differ from the portable loop, matcher %d of 2003; %s\n",
              quantiser, matcher, fastest ? "used by default" : "NOT used by default");
  // Under qemu only the two paths' ratio in one run means anything, not their times.
  const double portable = Seconds(SquaredDistanceTo8Bit, 200000), neon = Seconds(kSquaredDistanceTo8BitNeon, 200000);
  std::printf("quantiser distance, portable / NEON time in this run: %.2f\n", portable / neon);
  return quantiser == 0 && matcher == 0 && fastest ? 0 : 1;
}
