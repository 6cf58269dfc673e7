// What the change report costs while flying: keeping a route frame (PatrolRecord::route) — the frame thread
// scales the camera image to change.route_frames.max_width (RouteStrip::Scale), the change thread encodes it
// as JPEG (RouteStrip::Add) — on rendered village views at 376x240 and 752x480. One frame a second is kept.
#include <benchmark/benchmark.h>

#include "patrolmap/pipeline/route_strip.h"
#include "patrolmap/sim/renderer.h"
#include "patrolmap/sim/village.h"

namespace {

using namespace patrolmap;

cv::Mat RenderVillage(int width, int height) {
  const sim::Scene scene = sim::MakeVillage({1}).scene;
  const CameraIntrinsics camera{0.61 * width, 0.61 * width, width / 2.0 - 0.5, height / 2.0 - 0.5, width, height};
  sim::Renderer renderer(&scene, camera, sim::Lighting());
  cv::Mat image;
  renderer.Render({Eigen::Vector3d(20.0, -7.0, 3.0), M_PI / 2}, &image);
  return image;
}

void BM_KeepRouteFrame(benchmark::State& state) {
  const cv::Mat image = RenderVillage(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  change::RouteFrameOptions options;
  options.memory_mb = 1e4;  // no thinning: every frame is encoded and kept
  pipeline::RouteStrip strip(options);
  cv::Mat scaled;
  std::size_t bytes = 0;
  std::int64_t index = 0;
  for (auto _ : state) {
    strip.Scale(image, &scaled);
    RouteFrame frame;
    frame.timestamp_ns = SecondsToNs(static_cast<double>(index));
    frame.frame_index = index++;
    strip.Add(std::move(frame), scaled, false);
  }
  for (const RouteFrame& frame : strip.Take()) bytes += frame.jpeg.size();
  state.counters["kB_per_frame"] = static_cast<double>(bytes) / 1024.0 / static_cast<double>(index);
}
BENCHMARK(BM_KeepRouteFrame)->Args({376, 240})->Args({752, 480})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
