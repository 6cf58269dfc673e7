// Flight-log read throughput: every frame of each log given on the command line read and decoded to grey,
// through the FrameSource OpenLog picks (EuRoC folder, ROS 1 bag, ROS 2 bag, ...). Frames per second in
// the counter "frames/s".
//   read_benchmark [benchmark flags] LOG...
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "patrolmap/io/readers.h"

namespace {

using namespace patrolmap;

void ReadLog(benchmark::State& state, const std::string& path) {
  std::int64_t frames = 0;
  for (auto _ : state) {
    std::unique_ptr<io::FrameSource> source;
    if (!io::OpenLog(path, {}, &source).ok()) {
      state.SkipWithError((path + ": cannot open").c_str());
      return;
    }
    Frame frame;
    while (source->Next(true, &frame).ok()) {
      benchmark::DoNotOptimize(frame.image.data);
      ++frames;
    }
  }
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (int i = 1; i < argc; ++i) {
    const std::string path = argv[i];
    benchmark::RegisterBenchmark(("BM_Read/" + path).c_str(), [path](benchmark::State& state) { ReadLog(state, path); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
