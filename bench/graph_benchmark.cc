// Map file speed and size for 10,000 nodes of 200 features each (8-bit
// descriptors, a 160x102 thumbnail and a 150-word BoW vector per node).
#include <cmath>
#include <filesystem>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "patrolmap/graph/layout.h"
#include "patrolmap/graph/map_file.h"

namespace {

using namespace patrolmap;

graph::TopoMap TenThousandNodes() {
  graph::TopoMap map;
  cv::RNG rng(5);
  for (int i = 0; i < 10000; ++i) {
    KeyFrameNode node;
    node.flight = "flight-" + std::to_string(i / 2500);
    node.thumbnail = cv::Mat(102, 160, CV_8UC1);
    rng.fill(node.thumbnail, cv::RNG::UNIFORM, 0, 255);
    node.points.assign(200, cv::Point2f(1.0f, 2.0f));
    node.descriptors = cv::Mat(200, 128, CV_8UC1);
    rng.fill(node.descriptors, cv::RNG::UNIFORM, 0, 255);
    for (int w = 0; w < 150; ++w) node.bow.words.push_back(w * 60 + i % 60), node.bow.weights.push_back(1.0f / 150);
    map.AddNode(std::move(node));
    if (i % 2500 != 0) map.AddEdge(i - 1, i, graph::EdgeData{});
    if (i >= 2500 && i % 7 == 0) map.AddEdge(i, i - 2500, {graph::EdgeKind::kLoopClosure, 0.3, 0.5, 80});
  }
  return map;
}

const std::string kPath = (std::filesystem::temp_directory_path() / "patrolmap_bench_10k.pmap").string();

void BM_SaveMap10k(benchmark::State& state) {
  const graph::TopoMap map = TenThousandNodes();
  for (auto _ : state) {
    if (!graph::SaveMap(map, kPath).ok()) state.SkipWithError("save failed");
  }
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(kPath)) / 1e6;
}
BENCHMARK(BM_SaveMap10k)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_LoadMap10k(benchmark::State& state) {
  if (!std::filesystem::exists(kPath) && !graph::SaveMap(TenThousandNodes(), kPath).ok()) std::abort();
  graph::TopoMap map;
  for (auto _ : state) {
    if (!graph::LoadMap(kPath, &map).ok()) state.SkipWithError("load failed");
  }
  state.counters["nodes"] = map.node_count();
}
BENCHMARK(BM_LoadMap10k)->Unit(benchmark::kMillisecond)->Iterations(3);

// Layout of the same 10,000 nodes: 4 flights of 2,500 nodes one second apart with smoothly
// turning headings, and a loop closure every 7th node from the second flight on.
void BM_Layout10k(benchmark::State& state) {
  graph::TopoMap map = TenThousandNodes();
  for (int i = 0; i < map.node_count(); ++i) {
    map.mutable_node(i).timestamp_ns = SecondsToNs(i % 2500);
    map.mutable_node(i).heading = 0.01 * (i % 2500) + 0.3 * std::sin(0.05 * (i % 2500));
  }
  const graph::LayoutInput input = graph::LayoutInputOf(map);
  for (auto _ : state) {
    if (!graph::LayoutMap(input, graph::LayoutOptions{}, &map).ok()) state.SkipWithError("layout failed");
  }
  state.counters["loop_closures"] = map.loop_closure_count();
}
BENCHMARK(BM_Layout10k)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
