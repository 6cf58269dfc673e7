// Depth-stage speed: stereo depth of one rendered village pair (0.5 m baseline, 64 disparities) at 376x240
// and 752x480, with and without the left-right check (which matches the pair a second time), and at 752x480
// with 128 disparities or the near pass (both reach 1.8 m instead of 3.6 m); and the fusion of a
// depth frame with the frames before it (depth.stereo.fuse_frames) on the grid's ray lattice.
#include <algorithm>
#include <cmath>
#include <memory>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "patrolmap/depth/fusion.h"
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
  options.num_disparities = static_cast<int>(state.range(4));
  options.near_pass = state.range(5) != 0;
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
    ->ArgNames({"width", "lr_check", "edge_radius", "cancel_locking", "disparities", "near_pass"})
    ->Args({376, 1, 0, 0, 64, 0})
    ->Args({752, 1, 0, 0, 64, 0})
    ->Args({376, 0, 0, 0, 64, 0})
    ->Args({752, 0, 0, 0, 64, 0})
    ->Args({376, 1, 2, 0, 64, 0})
    ->Args({752, 1, 2, 0, 64, 0})
    ->Args({376, 1, 2, 1, 64, 0})
    ->Args({752, 1, 2, 1, 64, 0})
    ->Args({752, 1, 2, 0, 128, 0})
    ->Args({752, 1, 2, 0, 64, 1})
    ->Unit(benchmark::kMillisecond);

// One depth frame of the pair fused with `frames` before it, the camera 0.2 m further along each frame (a
// 1 m/s flight at the grid's 5 Hz), on the lattice of change.grid.rays_per_row 94.
void BM_DepthFusion(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Pair pair = RenderPair(width);
  std::unique_ptr<depth::StereoDepth> stereo;
  if (!depth::StereoDepth::Create(pair.calibration, depth::StereoOptions(), &stereo).ok()) {
    return state.SkipWithError("calibration");
  }
  cv::Mat raw, depth, error_scale;
  if (!stereo->Compute(pair.left, pair.right, &raw).ok()) return state.SkipWithError("compute");
  const int frames = static_cast<int>(state.range(1));
  depth::DepthFusion fusion(pair.calibration.left, depth::FusionOptions{frames, 2.0, stereo->RangeSigma(1.0)});
  const int step = std::max(1, static_cast<int>(std::lround(width / 94.0)));
  CameraPoseSample pose;
  for (int frame = 0; frame < frames; ++frame, pose.position.x() += 0.2) {
    raw.copyTo(depth);
    fusion.Fuse(pose, step, &depth, &error_scale);
  }
  for (auto _ : state) {
    raw.copyTo(depth);  // as the matcher hands each frame over
    fusion.Fuse(pose, step, &depth, &error_scale);
    benchmark::DoNotOptimize(depth.data);
  }
  double views_sum = 0.0;  // views averaged: 1 / scale^2 with no shared error
  int traced = 0;
  for (int y = step / 2; y < error_scale.rows; y += step) {
    for (int x = step / 2; x < error_scale.cols; x += step) {
      const float scale = error_scale.at<float>(y, x);
      if (scale > 0.0f) views_sum += 1.0 / (scale * scale), ++traced;
    }
  }
  state.counters["views"] = traced > 0 ? views_sum / traced : 0.0;
}
BENCHMARK(BM_DepthFusion)
    ->ArgNames({"width", "frames"})
    ->Args({376, 4})
    ->Args({752, 4})
    ->Args({752, 8})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
