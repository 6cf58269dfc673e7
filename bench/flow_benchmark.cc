// Per-frame cost of the key-location (flow) stage: edges, LK tracking, polar
// voting, response, smoothing and extremum detection on rendered street
// frames. Run with OpenCV on one thread, as on one core of the onboard target.
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/route.h"
#include "patrolmap/sim/village.h"

namespace {

using namespace patrolmap;

// Every 5th frame of the street flight (the frames the detector processes), at `width` x `height`.
const std::vector<cv::Mat>& StreetFrames(int width, int height) {
  static std::vector<cv::Mat> frames[2];
  std::vector<cv::Mat>& cached = frames[width > 400 ? 1 : 0];
  if (!cached.empty()) return cached;
  sim::SimulatedFlight flight = sim::MakeStreetFlight(sim::StreetOptions{});
  const double scale = width / 752.0;
  flight.camera = flight.camera.Scaled(scale);
  sim::Renderer renderer(&flight.scene, flight.camera);
  for (int i = 0; i < sim::FrameCount(flight); i += 5) {
    cv::Mat image;
    renderer.Render(sim::CameraPoseAt(flight, flight.trajectory(i / flight.frame_rate_hz)), &image);
    cached.push_back(image);
  }
  (void)height;
  return cached;
}

void BM_FlowStagePerProcessedFrame(benchmark::State& state) {
  cv::setNumThreads(1);
  const std::vector<cv::Mat>& frames = StreetFrames(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  flow::KeyLocationOptions options;
  options.frames.scale = 1.0;  // the frames given are already at processing size
  options.tracker.max_forward_backward_px = static_cast<double>(state.range(2));
  flow::CameraContext context;
  context.frame_rate_hz = options.frames.rate_hz;  // and already the processed ones
  flow::KeyLocationDetector detector(options, context);
  flow::DetectorOutput output;
  Frame frame;
  std::size_t next = 0;
  for (auto _ : state) {
    frame.image = frames[next % frames.size()];
    frame.index = static_cast<std::int64_t>(next);
    frame.timestamp_ns = SecondsToNs(next / 6.0);
    ++next;
    output.samples.clear();
    output.key_locations.clear();
    detector.Process(frame, &output);
    benchmark::DoNotOptimize(output.samples.data());
  }
  state.SetLabel(std::to_string(state.range(0)) + "x" + std::to_string(state.range(1)) +
                 (state.range(2) > 0 ? " forward-backward check" : ""));
}
BENCHMARK(BM_FlowStagePerProcessedFrame)
    ->Args({376, 240, 0})
    ->Args({752, 480, 0})
    ->Args({376, 240, 1})
    ->Args({752, 480, 1})
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

// Downscaling a native 752x480 frame to 376x240 (done once per processed frame when scale is 0.5).
void BM_DownscaleHalf(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat& image = StreetFrames(752, 480)[10];
  cv::Mat small;
  for (auto _ : state) {
    cv::resize(image, small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    benchmark::DoNotOptimize(small.data);
  }
}
BENCHMARK(BM_DownscaleHalf)->Unit(benchmark::kMicrosecond);

// Simulator rendering speed (frames per second = 1 / time).
void BM_RenderStreetFrame(benchmark::State& state) {
  sim::SimulatedFlight flight = sim::MakeStreetFlight(sim::StreetOptions{});
  flight.camera = flight.camera.Scaled(state.range(0) / 752.0);
  sim::Renderer renderer(&flight.scene, flight.camera);
  cv::Mat image;
  int i = 0;
  for (auto _ : state) {
    renderer.Render(sim::CameraPoseAt(flight, flight.trajectory((i++ % 600) / 30.0)), &image);
    benchmark::DoNotOptimize(image.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderStreetFrame)->Arg(376)->Arg(752)->Unit(benchmark::kMillisecond);

// Rendering the village along the double loop with 12 objects, lighting and sensor noise, as
// `patrolmap simulate` does (without writing PNGs).
void BM_RenderVillageFrame(benchmark::State& state) {
  sim::SimulatedFlight flight;
  sim::Village village = sim::MakeVillage({1});
  flight.scene = std::move(village.scene);
  flight.objects = sim::PlaceObjects(12, 1);
  sim::AddObjects(flight.objects, &flight.scene);
  sim::Route route;
  sim::RoutePreset("double-loop", &route);
  sim::FlyRoute(route, sim::RouteOptions{}, &flight);
  flight.camera = flight.camera.Scaled(state.range(0) / 752.0);
  sim::Renderer renderer(&flight.scene, flight.camera, sim::DrawLighting(1, 1));
  cv::Mat image;
  int frame = 0;
  for (auto _ : state) {
    const double t = std::fmod(frame * 7.3, flight.duration_s);  // spread over the whole flight
    renderer.Render(sim::CameraPoseAt(flight, flight.trajectory(t)), &image, frame++);
    benchmark::DoNotOptimize(image.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderVillageFrame)->Arg(376)->Arg(752)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
