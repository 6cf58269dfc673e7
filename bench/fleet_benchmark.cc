// Fleet scale (issue 17): place queries of the pruned inverted index against the exhaustive one on the
// simulator's places, merging maps, and the memory a real key frame's node holds.
//
// BM_LoadLargeMap and BM_MergeTwoMaps build synthetic maps; the largest need about 8 GB of memory and disk.
//
// BM_SimulatedPlaceQuery needs maps of simulated patrol series: PATROLMAP_BENCH_MAPS=a.pmap:b.pmap:... (for
// example the run_3 maps of scripts/change_study.sh; skipped without). Their nodes form one database, padded
// with `distractors` vectors drawn from the shipped vocabulary's word frequencies; each verified loop closure
// between flights is a query whose matched node must come back in the top 3.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/graph/map_file.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/pipeline/merge.h"
#include "patrolmap/place/place_recognizer.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"

namespace {

using namespace patrolmap;

struct PlaceQuery {
  vocab::BowVector bow;
  vocab::EntryId self = 0, match = 0;
  std::string flight;
};

struct Places {
  std::vector<vocab::BowVector> nodes;
  std::vector<std::string> flights;  // per node: map index and flight
  std::vector<PlaceQuery> queries;
};

const Places* LoadPlaces() {
  static std::unique_ptr<Places> places;
  static bool tried = false;
  if (tried) return places.get();
  tried = true;
  const char* list = std::getenv("PATROLMAP_BENCH_MAPS");
  if (list == nullptr) return nullptr;
  places = std::make_unique<Places>();
  std::stringstream paths(list);
  std::string path;
  for (int m = 0; std::getline(paths, path, ':'); ++m) {
    graph::TopoMap map;
    if (!graph::LoadMap(path, &map).ok()) std::abort();
    const auto base = static_cast<vocab::EntryId>(places->nodes.size());
    for (int i = 0; i < map.node_count(); ++i) {
      places->nodes.push_back(map.node(i).bow);
      places->flights.push_back(std::to_string(m) + "/" + map.node(i).flight);
    }
    for (const graph::TopoMap::Edge& e : map.Edges()) {
      if (e.data.kind != graph::EdgeKind::kLoopClosure || map.node(e.a).flight == map.node(e.b).flight) continue;
      places->queries.push_back({map.node(e.a).bow, base + e.a, base + e.b, places->flights[base + e.a]});
    }
  }
  return places.get();
}

// The places' nodes, then `distractors` vectors of 300 words drawn as often as the shipped vocabulary's
// training images held them; built once per count (Google Benchmark calls a benchmark several times).
const vocab::Database& PlacesWithDistractors(const Places& places, int distractors) {
  static std::map<int, std::unique_ptr<vocab::Database>> cache;
  std::unique_ptr<vocab::Database>& database = cache[distractors];
  if (database) return *database;
  vocab::Vocabulary vocabulary;
  if (!vocab::Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &vocabulary).ok())
    std::abort();
  database = std::make_unique<vocab::Database>(vocabulary.word_count());
  for (const vocab::BowVector& bow : places.nodes) database->Add(bow);
  const auto& idf = vocabulary.idf();
  std::vector<double> frequency(vocabulary.word_count());
  for (std::size_t w = 0; w < frequency.size(); ++w) frequency[w] = idf[w] > 0 ? std::exp(-idf[w]) : 0.0;
  std::discrete_distribution<vocab::WordId> draw(frequency.begin(), frequency.end());
  std::mt19937 rng(5);
  std::vector<vocab::WordId> words(300);
  vocab::BowVector bow;
  for (int i = 0; i < distractors; ++i) {
    for (auto& w : words) w = draw(rng);
    vocab::MakeBowVector(words, idf.data(), &bow);
    database->Add(bow);
  }
  return *database;
}

void BM_SimulatedPlaceQuery(benchmark::State& state) {
  const Places* places = LoadPlaces();
  if (places == nullptr || places->queries.empty()) {
    state.SkipWithError("set PATROLMAP_BENCH_MAPS to maps of simulated patrols");
    return;
  }
  const vocab::Database& database = PlacesWithDistractors(*places, static_cast<int>(state.range(0)));
  vocab::QueryOptions options;
  options.max_words = static_cast<int>(state.range(1));
  options.rescored = static_cast<int>(state.range(2));
  vocab::QueryOptions exhaustive;
  exhaustive.max_words = 0;
  std::vector<vocab::QueryResult> results, exact;
  const auto other_flight = [&](const PlaceQuery& q) {
    return [&](vocab::EntryId e) { return e >= places->nodes.size() || places->flights[e] != q.flight; };
  };
  std::size_t i = 0;
  for (auto _ : state) {
    const PlaceQuery& q = places->queries[i++ % places->queries.size()];
    database.Query(q.bow, 3, other_flight(q), &results, options);
    benchmark::DoNotOptimize(results.data());
  }
  int found = 0, found_exact = 0, same = 0;
  for (const PlaceQuery& q : places->queries) {
    database.Query(q.bow, 3, other_flight(q), &exact, exhaustive);
    database.Query(q.bow, 3, other_flight(q), &results, options);
    const auto has = [](const std::vector<vocab::QueryResult>& r, vocab::EntryId e) {
      return std::any_of(r.begin(), r.end(), [&](const vocab::QueryResult& x) { return x.entry == e; });
    };
    found += has(results, q.match);
    found_exact += has(exact, q.match);
    for (const vocab::QueryResult& e : exact) same += has(results, e.entry);
  }
  const double n = static_cast<double>(places->queries.size());
  state.counters["queries"] = n;
  state.counters["places"] = static_cast<double>(places->nodes.size());
  state.counters["recall@3"] = found / n;
  state.counters["exhaustive_recall@3"] = found_exact / n;
  state.counters["same_top3"] = same / (3 * n);
}
BENCHMARK(BM_SimulatedPlaceQuery)
    ->ArgNames({"distractors", "words", "rescored"})
    ->ArgsProduct({{0, 100000, 1000000}, {0, 16, 32, 64}, {100}})
    ->Unit(benchmark::kMillisecond);

// Synthetic key frames for the map benchmarks: `features` features spread over a 752x480 frame, random 8-bit
// descriptors, and words drawn as often as the shipped vocabulary's training images held them.
class SyntheticFrames {
 public:
  SyntheticFrames() {
    if (!vocab::Vocabulary::Load(VocabularyPath(), &vocabulary_).ok()) std::abort();
    const auto& idf = vocabulary_.idf();
    std::vector<double> frequency(vocabulary_.word_count());
    for (std::size_t w = 0; w < frequency.size(); ++w) frequency[w] = idf[w] > 0 ? std::exp(-idf[w]) : 0.0;
    draw_ = std::discrete_distribution<vocab::WordId>(frequency.begin(), frequency.end());
  }

  void set_thumbnail_width(int width) { thumbnail_width_ = width; }

  static std::string VocabularyPath() { return std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc"; }

  // A new key frame of `flight` at second `second`; with `seen` (the frame made just before this one), that
  // frame again: half its features kept and moved 6 px to the right, half new.
  KeyFrameNode Frame(const std::string& flight, int second, int features, const KeyFrameNode* seen) {
    KeyFrameNode node;
    node.flight = flight;
    node.thumbnail = cv::Mat(thumbnail_width_ * 480 / 752, thumbnail_width_, CV_8UC1);
    rng_.fill(node.thumbnail, cv::RNG::UNIFORM, 0, 255);
    node.timestamp_ns = SecondsToNs(second);
    node.frame_index = second;
    node.descriptors = cv::Mat(features, 128, CV_8UC1);
    rng_.fill(node.descriptors, cv::RNG::UNIFORM, 0, 64);
    words_.resize(features);
    for (int f = 0; f < features; ++f) {
      node.points.emplace_back(rng_.uniform(0.0f, 752.0f), rng_.uniform(0.0f, 480.0f));
      words_[f] = draw_(engine_);
      if (seen != nullptr && f % 2 == 0 && f < seen->descriptors.rows) {
        node.points[f] = seen->points[f] + cv::Point2f(6.0f, 0.0f);
        seen->descriptors.row(f).copyTo(node.descriptors.row(f));
        words_[f] = seen_words_[f];
      }
    }
    vocab::MakeBowVector(words_, vocabulary_.idf().data(), &node.bow);
    seen_words_ = words_;
    return node;
  }

  // Flight "a" of `nodes` key frames one second apart, each linked to the one before, into `first`; with
  // `second`, flight "b", later, that sees each of a's frames again (made right after it).
  void Flights(int nodes, int features, graph::TopoMap* first, graph::TopoMap* second) {
    for (graph::TopoMap* map : {first, second}) {
      if (map != nullptr) map->set_vocabulary({vocabulary_.Fingerprint(), "default.pmvoc"});
    }
    for (int i = 0; i < nodes; ++i) {
      const int a = first->AddNode(Frame("a", i, features, nullptr));
      if (i > 0) first->AddEdge(a - 1, a, graph::EdgeData{});
      if (second == nullptr) continue;
      const int b = second->AddNode(Frame("b", 100000 + i, features, &first->node(a)));
      if (i > 0) second->AddEdge(b - 1, b, graph::EdgeData{});
    }
  }

 private:
  vocab::Vocabulary vocabulary_;
  std::discrete_distribution<vocab::WordId> draw_;
  std::mt19937 engine_{17};
  cv::RNG rng_{17};
  std::vector<vocab::WordId> words_, seen_words_;
  int thumbnail_width_ = 160;
};

double PeakMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// Loading a map of one flight: `nodes` nodes of `features` features and a thumbnail `thumbnail` pixels wide
// (a map keeps 160). The million-node map has small nodes so that it fits in this machine's memory.
void BM_LoadLargeMap(benchmark::State& state) {
  const auto nodes = static_cast<int>(state.range(0));
  const std::string path = (std::filesystem::temp_directory_path() / "patrolmap_bench_large.pmap").string();
  {
    graph::TopoMap map;
    SyntheticFrames frames;
    frames.set_thumbnail_width(static_cast<int>(state.range(2)));
    frames.Flights(nodes, static_cast<int>(state.range(1)), &map, nullptr);
    if (!graph::SaveMap(map, path).ok()) std::abort();
  }
  graph::TopoMap loaded;
  for (auto _ : state) {
    loaded = graph::TopoMap();
    const Status status = graph::LoadMap(path, &loaded);
    if (!status.ok()) state.SkipWithError(status.message().c_str());
  }
  state.counters["nodes"] = loaded.node_count();
  state.counters["file_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.counters["peak_MB"] = PeakMegabytes();
  std::filesystem::remove(path);
}
BENCHMARK(BM_LoadLargeMap)
    ->ArgNames({"nodes", "features", "thumbnail"})
    ->Args({100000, 64, 160})
    ->Args({1000000, 32, 40})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// `patrolmap merge` of two one-flight maps of `nodes` nodes (150 features) where the second flight revisits the
// first: every node of the second map should close a loop to its twin in the first.
void BM_MergeTwoMaps(benchmark::State& state) {
  const auto nodes = static_cast<int>(state.range(0));
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "patrolmap_bench_merge";
  std::filesystem::create_directories(folder);
  pipeline::MergeRequest request;
  request.maps = {(folder / "a.pmap").string(), (folder / "b.pmap").string()};
  request.out = (folder / "merged").string();
  request.vocabulary_path = SyntheticFrames::VocabularyPath();
  {
    graph::TopoMap a, b;
    SyntheticFrames().Flights(nodes, 150, &a, &b);
    if (!graph::SaveMap(a, request.maps[0]).ok() || !graph::SaveMap(b, request.maps[1]).ok()) std::abort();
  }
  pipeline::MergeOutcome outcome;
  for (auto _ : state) {
    std::filesystem::remove_all(request.out);
    const Status status = pipeline::RunMerge(request, &outcome);
    if (!status.ok()) state.SkipWithError(status.message().c_str());
  }
  state.counters["nodes"] = outcome.nodes;
  state.counters["closures"] = outcome.loop_closures;
  state.counters["query_s"] = outcome.seconds_query;
  state.counters["verify_s"] = outcome.seconds_verify;
  state.counters["peak_MB"] = PeakMegabytes();
  std::filesystem::remove_all(folder);
}
BENCHMARK(BM_MergeTwoMaps)->Arg(1000)->Arg(50000)->Unit(benchmark::kSecond)->Iterations(1);

// Memory per node on real key frames, as `patrolmap map` and `patrol` hold it: every image, resized by `scale`
// percent (the map command describes key frames at flow.frame.scale, 50 %), goes through
// PlaceRecognizer::AddKeyFrame (describe, keep the descriptors as place.descriptor_bits says, query, verify,
// add) and then into a TopoMap with a 160-pixel thumbnail, as the map command builds it. The images come from
// PATROLMAP_BENCH_IMAGES (a folder; default: the KITTI excerpt beside the repository), cycled. The growth of the
// resident set between node `warmup` and the last is divided by the nodes added in between (resident_KB); the
// other counters are the bytes each part keeps, averaged.
std::vector<cv::Mat> RealImages() {
  const char* folder = std::getenv("PATROLMAP_BENCH_IMAGES");
  const std::filesystem::path path =
      folder != nullptr ? folder : std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data/kitti_seq2/image_l";
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(path, error)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<cv::Mat> images;
  for (const auto& file : files) {
    cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (!image.empty()) images.push_back(image);
  }
  return images;
}

double ResidentKilobytes() {
  std::ifstream statm("/proc/self/statm");
  double size = 0.0, resident = 0.0;
  statm >> size >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1024.0;
}

void BM_RealNodeMemory(benchmark::State& state) {
  const std::vector<cv::Mat> images = RealImages();
  if (images.empty()) return state.SkipWithError("no images (PATROLMAP_BENCH_IMAGES, or ../shared/data)");
  const auto nodes = static_cast<int>(state.range(1)), warmup = 200;
  std::vector<cv::Mat> scaled(images.size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    const double scale = static_cast<double>(state.range(2)) / 100.0;
    cv::resize(images[i], scaled[i], cv::Size(), scale, scale, cv::INTER_AREA);
  }
  place::PlaceOptions options;
  options.descriptor_bits = static_cast<int>(state.range(0));
  vocab::Vocabulary vocabulary;
  if (!vocab::Vocabulary::Load(SyntheticFrames::VocabularyPath(), &vocabulary).ok()) std::abort();
  double resident_kb = 0.0, descriptors = 0.0, points = 0.0, words = 0.0, thumbnails = 0.0;
  for (auto _ : state) {
    place::PlaceRecognizer recognizer(&vocabulary, options);
    graph::TopoMap map;
    double start_kb = 0.0;
    for (int i = 0; i < warmup + nodes; ++i) {
      if (i == warmup) start_kb = ResidentKilobytes();
      place::KeyFrame key_frame{"real", 0, i, scaled[i % scaled.size()], false};
      place::PlaceResult result;
      if (!recognizer.AddKeyFrame(key_frame, &result).ok()) std::abort();
      KeyFrameNode data = std::move(result.described);  // descriptors shared with the recognizer, as in mapping
      data.frame_index = i;
      const double scale = 160.0 / key_frame.image.cols;
      cv::resize(key_frame.image, data.thumbnail, cv::Size(), scale, scale, cv::INTER_AREA);
      map.AddNode(std::move(data));
    }
    resident_kb = (ResidentKilobytes() - start_kb) / nodes;
    for (int i = 0; i < map.node_count(); ++i) {
      const KeyFrameNode& n = map.node(i);
      descriptors += static_cast<double>(n.descriptors.total() * n.descriptors.elemSize());
      points += 2.0 * static_cast<double>(n.points.size() * sizeof(cv::Point2f));  // the recognizer's and the map's
      words += static_cast<double>(n.bow.words.size());
      thumbnails += static_cast<double>(n.thumbnail.total());
    }
    const double count = map.node_count();
    descriptors /= count, points /= count, words /= count, thumbnails /= count;
  }
  state.counters["resident_KB"] = resident_kb;
  state.counters["descriptors_KB"] = descriptors / 1024.0;
  state.counters["points_KB"] = points / 1024.0;
  // A word is kept three times: the database's entry and posting (8 bytes each) and the map's BoW vector (8).
  state.counters["bow_KB"] = 24.0 * words / 1024.0;
  state.counters["thumbnail_KB"] = thumbnails / 1024.0;
  state.counters["features"] = descriptors / (options.descriptor_bits == 4 ? 64.0 : 128.0);
}
BENCHMARK(BM_RealNodeMemory)
    ->ArgNames({"bits", "nodes", "scale"})
    ->Args({8, 2000, 50})
    ->Args({4, 2000, 50})
    ->Args({8, 2000, 100})
    ->Args({4, 2000, 100})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
