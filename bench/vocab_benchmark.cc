// Vocabulary and database speed: loading a one-million-word vocabulary file,
// quantising descriptors, and querying databases of 1k, 10k and 100k entries.
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

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

}  // namespace

BENCHMARK_MAIN();
