// Vocabulary and database speed: loading a one-million-word vocabulary file,
// quantising descriptors, and querying databases of 1k, 10k and 100k entries.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <random>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "patrolmap/place/place_recognizer.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"

namespace {

using namespace patrolmap;

cv::Mat RandomDescriptors(int rows, std::uint32_t seed) {
  cv::Mat descriptors(rows, 128, CV_32F);
  cv::RNG rng(seed);
  rng.fill(descriptors, cv::RNG::UNIFORM, 0.0, 255.0);
  return descriptors;
}

// A k=32, L=4 vocabulary (up to 32^4 = 1,048,576 words) trained once, one k-means iteration per node, on
// 3 million random descriptors, and cached in the temp folder.
const std::string& MillionWordFile() {
  static const std::string path = (std::filesystem::temp_directory_path() / "patrolmap_bench_1M.voc").string();
  vocab::Vocabulary probe;
  if (vocab::Vocabulary::Load(path, &probe).ok() && probe.word_count() > 900000) return path;
  vocab::VocabularyOptions options;
  options.branching = 32;
  options.depth = 4;
  options.max_iterations = 1;
  vocab::Vocabulary vocabulary;
  std::vector<cv::Mat> images;
  for (int i = 0; i < 50; ++i) images.push_back(RandomDescriptors(60000, i + 1));
  if (!vocab::Vocabulary::Train(images, options, &vocabulary).ok() || !vocabulary.Save(path).ok()) std::abort();
  return path;
}

void BM_LoadMillionWordVocabulary(benchmark::State& state) {
  const std::string& path = MillionWordFile();
  vocab::Vocabulary vocabulary;
  for (auto _ : state) {
    if (!vocab::Vocabulary::Load(path, &vocabulary).ok()) state.SkipWithError("load failed");
  }
  state.counters["words"] = vocabulary.word_count();
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
}
BENCHMARK(BM_LoadMillionWordVocabulary)->Unit(benchmark::kMillisecond)->Iterations(10);

void BM_Transform1000Descriptors(benchmark::State& state) {
  vocab::Vocabulary vocabulary;
  if (!vocab::Vocabulary::Load(MillionWordFile(), &vocabulary).ok()) std::abort();
  const cv::Mat descriptors = RandomDescriptors(1000, 99);
  vocab::BowVector bow;
  for (auto _ : state) {
    vocabulary.Transform(descriptors, &bow);
    benchmark::DoNotOptimize(bow.words.data());
  }
}
BENCHMARK(BM_Transform1000Descriptors)->Unit(benchmark::kMillisecond);

// Quantising real RootSIFT features (the defaults: the 800 strongest of each image) in the shipped vocabulary,
// as place recognition does for each key frame. The images are opencv-doc's (skipped without it).
void BM_QuantizeRealFeatures(benchmark::State& state) {
  vocab::Vocabulary vocabulary;
  if (!vocab::Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &vocabulary).ok())
    std::abort();
  const std::string folder = "/usr/share/doc/opencv-doc/examples/data/";
  std::vector<cv::Mat> frames;
  for (const char* name : {"aero1.jpg", "graf1.png", "leuvenA.jpg", "building.jpg"}) {
    const cv::Mat image = cv::imread(folder + name, cv::IMREAD_GRAYSCALE);
    if (image.empty()) continue;
    std::vector<cv::Point2f> points;
    frames.emplace_back();
    place::DescribeFeatures(image, place::PlaceOptions{}, &points, &frames.back());
  }
  if (frames.empty()) {
    state.SkipWithError("opencv-doc's example images are not installed");
    return;
  }
  std::vector<vocab::WordId> words;
  std::int64_t descriptors = 0;
  for (auto _ : state) {
    for (const cv::Mat& frame : frames) {
      vocabulary.Quantize(frame, &words);
      descriptors += frame.rows;
    }
    benchmark::DoNotOptimize(words.data());
  }
  state.counters["per_1000"] = benchmark::Counter(static_cast<double>(descriptors) / 1000.0,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["frames"] = static_cast<double>(frames.size());
}
BENCHMARK(BM_QuantizeRealFeatures)->Unit(benchmark::kMillisecond);

// Databases of random 400-word vectors over a 10k-word vocabulary (k=10, L=4).
void BM_DatabaseQuery(benchmark::State& state) {
  const int entries = static_cast<int>(state.range(0));
  constexpr int kWords = 10000;
  std::mt19937 rng(7);
  std::uniform_int_distribution<vocab::WordId> word(0, kWords - 1);
  const std::vector<float> idf(kWords, 1.0f);
  vocab::Database database(kWords);
  std::vector<vocab::WordId> words(400);
  vocab::BowVector bow;
  for (int e = 0; e < entries; ++e) {
    for (auto& w : words) w = word(rng);
    vocab::MakeBowVector(words, idf.data(), &bow);
    database.Add(bow);
  }
  for (auto& w : words) w = word(rng);
  vocab::MakeBowVector(words, idf.data(), &bow);
  std::vector<vocab::QueryResult> results;
  for (auto _ : state) {
    database.Query(bow, 3, {}, &results);
    benchmark::DoNotOptimize(results.data());
  }
}
BENCHMARK(BM_DatabaseQuery)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

// Databases that look like a fleet's maps: vectors of the shipped vocabulary (9,709 words), each of 300
// features whose words are drawn as often as the vocabulary's training images held them (document frequency
// exp(-idf)), so the posting lists are as long as real ones. Queries are entries seen again: half the features
// of an entry and half new ones.
struct RealisticDatabase {
  vocab::Vocabulary vocabulary;
  std::unique_ptr<vocab::Database> database;
  std::vector<vocab::BowVector> queries;
};

constexpr int kFeaturesPerEntry = 300;

const RealisticDatabase& RealisticOf(int entries) {
  static std::map<int, std::unique_ptr<RealisticDatabase>> cache;
  auto& slot = cache[entries];
  if (slot) return *slot;
  slot = std::make_unique<RealisticDatabase>();
  if (!vocab::Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &slot->vocabulary).ok())
    std::abort();
  const auto& idf = slot->vocabulary.idf();
  std::vector<double> frequency(slot->vocabulary.word_count());
  for (std::size_t w = 0; w < frequency.size(); ++w) frequency[w] = idf[w] > 0 ? std::exp(-idf[w]) : 0.0;
  std::discrete_distribution<vocab::WordId> draw(frequency.begin(), frequency.end());
  std::mt19937 rng(11);
  slot->database = std::make_unique<vocab::Database>(slot->vocabulary.word_count());
  std::vector<vocab::WordId> words(kFeaturesPerEntry);
  std::vector<std::vector<vocab::WordId>> kept;
  vocab::BowVector bow;
  for (int e = 0; e < entries; ++e) {
    for (auto& w : words) w = draw(rng);
    vocab::MakeBowVector(words, idf.data(), &bow);
    slot->database->Add(bow);
    if (e % std::max(1, entries / 100) == 0) kept.push_back(words);
  }
  for (std::vector<vocab::WordId>& seen : kept) {
    for (std::size_t i = 0; i < seen.size(); i += 2) seen[i] = draw(rng);
    vocab::MakeBowVector(seen, idf.data(), &bow);
    slot->queries.push_back(bow);
  }
  return *slot;
}

// Top-3 queries, exhaustive (words 0) or two-stage (the lists of the query's `words` words with the most weight
// per posting, then `rescored` entries scored exactly; where the skipped lists hold fewer postings than the
// default minimum, exhaustive). "same_top3" is the share of the exhaustive top 3 that the query returns,
// "recall@3" the share of queries whose source entry it returns, over 100 queries.
void BM_RealisticQuery(benchmark::State& state) {
  const RealisticDatabase& data = RealisticOf(static_cast<int>(state.range(0)));
  vocab::QueryOptions options;
  options.max_words = static_cast<int>(state.range(1));
  options.rescored = static_cast<int>(state.range(2));
  vocab::QueryOptions exhaustive;
  exhaustive.max_words = 0;
  std::vector<vocab::QueryResult> results, exact;
  std::size_t q = 0;
  for (auto _ : state) {
    data.database->Query(data.queries[q++ % data.queries.size()], 3, {}, &results, options);
    benchmark::DoNotOptimize(results.data());
  }
  int found = 0, wanted = 0, source = 0;
  const int step = std::max(1, static_cast<int>(state.range(0)) / 100);
  for (std::size_t i = 0; i < data.queries.size(); ++i) {
    data.database->Query(data.queries[i], 3, {}, &exact, exhaustive);
    data.database->Query(data.queries[i], 3, {}, &results, options);
    for (const vocab::QueryResult& e : exact) {
      ++wanted;
      found += std::any_of(results.begin(), results.end(), [&](const auto& r) { return r.entry == e.entry; });
    }
    const auto from = static_cast<vocab::EntryId>(i * step);
    source += std::any_of(results.begin(), results.end(), [&](const auto& r) { return r.entry == from; });
  }
  state.counters["same_top3"] = wanted > 0 ? static_cast<double>(found) / wanted : 1.0;
  state.counters["recall@3"] = static_cast<double>(source) / data.queries.size();
}
BENCHMARK(BM_RealisticQuery)
    ->ArgNames({"entries", "words", "rescored"})
    ->ArgsProduct({{1000, 10000, 100000, 1000000}, {0, 32, 64}, {100}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
