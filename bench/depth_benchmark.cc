// Depth-stage speed: stereo depth of one rendered village pair (0.5 m baseline, 64 disparities) at 376x240
// and 752x480, with and without the left-right check (which matches the pair a second time).
#include <memory>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "patrolmap/depth/stereo.h"
#include "patrolmap/sim/renderer.h"
#include "patrolmap/sim/village.h"

namespace {

using namespace patrolmap;

struct Pair {
  StereoCalibration calibration;
  cv::Mat left, right;
};

// The camera on the village's south street looking north, and a second one 0.5 m to its right.
Pair RenderPair(int width) {
  const double scale = width / 376.0;
  const CameraIntrinsics camera{229.0 * scale, 229.0 * scale, 187.5 * scale,
                                119.5 * scale, width,         static_cast<int>(240 * scale)};
  Pair pair;
  pair.calibration.left = pair.calibration.right = camera;
  pair.calibration.right_from_left_translation = Eigen::Vector3d(-0.5, 0.0, 0.0);
  const sim::Scene scene = sim::MakeVillage({1}).scene;
  sim::Renderer renderer(&scene, camera);
  sim::CameraPose pose{Eigen::Vector3d(20.0, -7.0, 3.0), M_PI / 2};
  renderer.Render(pose, &pair.left);
  pose.position += 0.5 * sim::WorldFromCameraRotation(pose.yaw).col(0);
  renderer.Render(pose, &pair.right, 1);
  return pair;
}

void BM_StereoDepth(benchmark::State& state) {
  const Pair pair = RenderPair(static_cast<int>(state.range(0)));
  depth::StereoOptions options;
  options.lr_check = state.range(1) != 0;
  options.edge_radius_px = static_cast<int>(state.range(2));
  options.cancel_pixel_locking = state.range(3) != 0;
  std::unique_ptr<depth::StereoDepth> stereo;
  if (!depth::StereoDepth::Create(pair.calibration, options, &stereo).ok()) return state.SkipWithError("calibration");
  cv::Mat depth;
  for (auto _ : state) {
    if (!stereo->Compute(pair.left, pair.right, &depth).ok()) return state.SkipWithError("compute");
    benchmark::DoNotOptimize(depth.data);
  }
  state.counters["known"] = static_cast<double>(cv::countNonZero(depth)) / depth.total();
}
BENCHMARK(BM_StereoDepth)
    ->ArgNames({"width", "lr_check", "edge_radius", "cancel_locking"})
    ->Args({376, 1, 0, 0})
    ->Args({752, 1, 0, 0})
    ->Args({376, 0, 0, 0})
    ->Args({752, 0, 0, 0})
    ->Args({376, 1, 2, 0})
    ->Args({752, 1, 2, 0})
    ->Args({376, 1, 2, 1})
    ->Args({752, 1, 2, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
