#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "../src/vocab/kmeans.h"
#include "patrolmap/core/checksum.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"
#include "recompute_checksums.h"
#include "test_util.h"

namespace patrolmap::vocab {
namespace {

// `clusters` well-separated Gaussian blobs of `per_cluster` points in `dimension` dims (values >= 0).
cv::Mat Blobs(int clusters, int per_cluster, int dimension, std::uint32_t seed, std::vector<int>* labels) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 2.0f);
  std::uniform_real_distribution<float> centre(20.0f, 235.0f);
  cv::Mat points(clusters * per_cluster, dimension, CV_32F);
  labels->clear();
  for (int c = 0; c < clusters; ++c) {
    std::vector<float> mean(dimension);
    for (float& value : mean) value = centre(rng);
    for (int i = 0; i < per_cluster; ++i) {
      float* row = points.ptr<float>(c * per_cluster + i);
      for (int d = 0; d < dimension; ++d) row[d] = std::max(0.0f, mean[d] + noise(rng));
      labels->push_back(c);
    }
  }
  return points;
}

TEST(KMeans, RecoversSeparatedClustersWithinTheIterationCap) {
  std::vector<int> labels;
  const cv::Mat points = Blobs(4, 50, 8, 3, &labels);
  std::vector<std::uint32_t> indices(points.rows);
  for (int i = 0; i < points.rows; ++i) indices[i] = i;
  std::mt19937 rng(1);
  Clustering clustering;
  KMeans(points.ptr<float>(), 8, indices, 4, 10, &rng, &clustering);
  EXPECT_EQ(clustering.clusters, 4);
  EXPECT_LE(clustering.iterations, 10);
  std::set<std::pair<int, int>> pairs;
  for (int i = 0; i < points.rows; ++i) pairs.insert({labels[i], clustering.assignment[i]});
  EXPECT_EQ(pairs.size(), 4u);  // a one-to-one map between blobs and clusters
}

TEST(KMeans, FewerPointsThanClustersGiveOneClusterEach) {
  const cv::Mat points = (cv::Mat_<float>(2, 2) << 1, 2, 3, 4);
  std::mt19937 rng(1);
  Clustering clustering;
  KMeans(points.ptr<float>(), 2, {0, 1}, 5, 10, &rng, &clustering);
  EXPECT_EQ(clustering.clusters, 2);
  EXPECT_EQ(clustering.assignment, (std::vector<int>{0, 1}));
}

Vocabulary TrainOnBlobs(std::uint32_t seed, std::vector<int>* labels, cv::Mat* points) {
  *points = Blobs(16, 40, 16, 9, labels);
  std::vector<cv::Mat> images;
  for (int i = 0; i < points->rows; i += 40) images.push_back(points->rowRange(i, i + 40));  // one blob per image
  VocabularyOptions options;
  options.branching = 4;
  options.depth = 2;
  options.seed = seed;
  Vocabulary vocabulary;
  EXPECT_TRUE(Vocabulary::Train(images, options, &vocabulary).ok());
  return vocabulary;
}

TEST(Vocabulary, TreeOnKnownClustersGivesOneWordPerBlob) {
  std::vector<int> labels;
  cv::Mat points;
  const cv::Mat before = Blobs(16, 40, 16, 9, &labels);
  const Vocabulary vocabulary = TrainOnBlobs(1, &labels, &points);
  EXPECT_EQ(cv::norm(points, before, cv::NORM_INF), 0.0);  // training never writes the input
  EXPECT_LE(vocabulary.word_count(), 16);
  std::vector<WordId> words;
  vocabulary.Quantize(points, &words);
  std::set<std::pair<int, WordId>> pairs;
  std::set<WordId> distinct(words.begin(), words.end());
  for (std::size_t i = 0; i < words.size(); ++i) pairs.insert({labels[i], words[i]});
  EXPECT_GE(distinct.size(), 12u);               // most blobs get a word of their own ...
  EXPECT_LE(pairs.size(), distinct.size() + 2);  // ... and a blob hardly ever splits
  for (float idf : vocabulary.idf()) EXPECT_GE(idf, 0.0f);
}

// IDF is log(N / n_i) (paper 002 §III-B, Nister and Stewenius): N = 16 training images (one blob each),
// n_i the images whose descriptors fall in word i, counted here by quantising each image.
TEST(Vocabulary, IdfIsTheLogOfImagesOverImagesHoldingTheWord) {
  std::vector<int> labels;
  cv::Mat points;
  const Vocabulary vocabulary = TrainOnBlobs(1, &labels, &points);
  std::vector<int> holders(vocabulary.word_count(), 0);
  for (int image = 0; image < 16; ++image) {
    std::vector<WordId> words;
    vocabulary.Quantize(points.rowRange(image * 40, image * 40 + 40), &words);
    for (WordId word : std::set<WordId>(words.begin(), words.end())) ++holders[word];
  }
  int checked = 0;
  for (int word = 0; word < vocabulary.word_count(); ++word) {
    if (holders[word] == 0) continue;
    EXPECT_NEAR(vocabulary.idf()[word], std::log(16.0 / holders[word]), 1e-5) << "word " << word;
    ++checked;
  }
  EXPECT_GE(checked, 12);
}

TEST(Vocabulary, TrainingIsDeterministicForASeed) {
  std::vector<int> labels;
  cv::Mat points;
  testing::TempDir dir;
  ASSERT_TRUE(TrainOnBlobs(5, &labels, &points).Save(dir / "a.voc").ok());
  ASSERT_TRUE(TrainOnBlobs(5, &labels, &points).Save(dir / "b.voc").ok());
  EXPECT_EQ(testing::ReadText(dir / "a.voc"), testing::ReadText(dir / "b.voc"));
}

TEST(Vocabulary, BadTrainingInputIsRefused) {
  Vocabulary vocabulary;
  EXPECT_EQ(Vocabulary::Train({}, VocabularyOptions{}, &vocabulary).code(), StatusCode::kInvalidArgument);
  VocabularyOptions options;
  options.branching = 1;
  EXPECT_EQ(Vocabulary::Train({cv::Mat::ones(3, 4, CV_32F)}, options, &vocabulary).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(Vocabulary::Train({cv::Mat::ones(3, 4, CV_8U)}, VocabularyOptions{}, &vocabulary).code(),
            StatusCode::kInvalidArgument);
}

TEST(BowVector, IdenticalScoresOneDisjointZero) {
  const std::vector<float> idf = {1.0f, 2.0f, 0.5f, 1.0f, 0.0f};
  BowVector a, b, c;
  MakeBowVector({0, 1, 1, 2}, idf.data(), &a);
  MakeBowVector({0, 1, 1, 2}, idf.data(), &b);
  MakeBowVector({3, 4}, idf.data(), &c);  // word 4 has idf 0 and is dropped
  EXPECT_NEAR(L1Score(a, b), 1.0, 1e-6);
  EXPECT_NEAR(L1Score(a, c), 0.0, 1e-12);
  ASSERT_EQ(c.words, (std::vector<WordId>{3}));
  float sum = 0.0f;
  for (float weight : a.weights) sum += weight;
  EXPECT_NEAR(sum, 1.0f, 1e-6);
  EXPECT_NEAR(a.weights[1], 4.0 / 5.5, 1e-6);  // tf 2 x idf 2 of 1 + 4 + 0.5
  BowVector d;
  MakeBowVector({0, 1}, idf.data(), &d);
  EXPECT_NEAR(L1Score(a, d), L1Score(d, a), 1e-12);
  EXPECT_GT(L1Score(a, d), 0.3);
  EXPECT_LT(L1Score(a, d), 1.0);
}

class VocabularyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<int> labels;
    cv::Mat points;
    vocabulary_ = TrainOnBlobs(2, &labels, &points);
    points_ = points;
    ASSERT_TRUE(vocabulary_.Save(dir_ / "v.voc").ok());
    bytes_ = testing::ReadText(dir_ / "v.voc");
  }
  Status LoadBytes(const std::string& bytes) {
    std::ofstream(dir_ / "x.voc", std::ios::binary) << bytes;
    Vocabulary loaded;
    return Vocabulary::Load(dir_ / "x.voc", &loaded);
  }
  testing::TempDir dir_;
  Vocabulary vocabulary_;
  cv::Mat points_;
  std::string bytes_;
};

TEST_F(VocabularyFileTest, RoundTripGivesTheSameWords) {
  Vocabulary loaded;
  ASSERT_TRUE(Vocabulary::Load(dir_ / "v.voc", &loaded).ok());
  EXPECT_EQ(loaded.word_count(), vocabulary_.word_count());
  EXPECT_EQ(loaded.idf(), vocabulary_.idf());
  std::vector<WordId> a, b;
  vocabulary_.Quantize(points_, &a);
  loaded.Quantize(points_, &b);
  EXPECT_EQ(a, b);
}

TEST_F(VocabularyFileTest, EveryCorruptCaseFailsWithAMessage) {
  EXPECT_NE(LoadBytes(bytes_.substr(0, bytes_.size() / 2)).message().find("truncated vocabulary"), std::string::npos);
  EXPECT_NE(LoadBytes(bytes_.substr(0, 20)).message().find("truncated vocabulary (header"), std::string::npos);
  std::string flipped = bytes_;
  flipped[bytes_.size() / 2] ^= 0x40;
  EXPECT_NE(LoadBytes(flipped).message().find("checksum mismatch"), std::string::npos);
  EXPECT_NE(LoadBytes("GIF89a this is something else").message().find("not a patrolmap vocabulary"), std::string::npos);
  EXPECT_NE(LoadBytes("").message().find("not a patrolmap vocabulary"), std::string::npos);
  std::string newer = bytes_;
  const std::uint32_t version = 7;
  std::memcpy(newer.data() + 8, &version, 4);
  EXPECT_NE(LoadBytes(newer).message().find("version 7 is newer"), std::string::npos);
  EXPECT_NE(LoadBytes(bytes_ + "extra").message().find("trailing bytes"), std::string::npos);
  Vocabulary loaded;
  EXPECT_EQ(Vocabulary::Load(dir_ / "missing.voc", &loaded).code(), StatusCode::kNotFound);
}

// Truncations at 64 offsets and 200 single-bit flips with the checksum recomputed (fixed seed): each file
// loads the same way twice and quantises, or fails with a message that names it.
TEST_F(VocabularyFileTest, DamageBehindAGoodChecksumLoadsIdenticallyOrFailsNamingTheFile) {
  std::vector<std::string> cases;
  for (int i = 0; i < 64; ++i) cases.push_back(bytes_.substr(0, bytes_.size() * i / 64));
  std::mt19937 rng(18);
  for (int i = 0; i < 200; ++i) {
    std::string flipped = bytes_;
    const std::size_t bit = std::uniform_int_distribution<std::size_t>(0, 8 * bytes_.size() - 1)(rng);
    flipped[bit / 8] = static_cast<char>(flipped[bit / 8] ^ (1 << (bit % 8)));
    testing::RecomputeVocabularyChecksum(&flipped);
    cases.push_back(flipped);
  }
  const std::string path = dir_ / "damaged.voc";
  int loaded = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << cases[i];
    Vocabulary first, second;
    const Status a = Vocabulary::Load(path, &first), b = Vocabulary::Load(path, &second);
    ASSERT_EQ(a.message(), b.message()) << "case " << i;
    if (!a.ok()) {
      EXPECT_NE(a.message().find(path), std::string::npos) << "case " << i << ": " << a.message();
      continue;
    }
    ++loaded;
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(first.Fingerprint(), second.Fingerprint()) << "case " << i;
    std::vector<WordId> words_a, words_b;
    first.Quantize(points_, &words_a);
    second.Quantize(points_, &words_b);
    EXPECT_EQ(words_a, words_b) << "case " << i;
  }
  EXPECT_LT(loaded, 200);  // flips in the tree's links are refused by the content checks
  EXPECT_GT(loaded, 50);   // flips in centres and weights pass the recomputed checksum (138 at seed 18)
}

TEST(Database, QueryRanksByScoreAndHonoursExclusions) {
  const std::vector<float> idf(10, 1.0f);
  BowVector a, b, c, query;
  MakeBowVector({0, 1, 2, 3}, idf.data(), &a);
  MakeBowVector({0, 1, 7, 8}, idf.data(), &b);
  MakeBowVector({5, 6}, idf.data(), &c);
  Database database(10);
  database.Add(a), database.Add(b), database.Add(c);
  MakeBowVector({0, 1, 2, 3}, idf.data(), &query);
  std::vector<QueryResult> results;
  database.Query(query, 3, {}, &results);
  ASSERT_EQ(results.size(), 2u);  // c shares no word
  EXPECT_EQ(results[0].entry, 0u);
  EXPECT_NEAR(results[0].score, 1.0, 1e-6);
  EXPECT_EQ(results[1].entry, 1u);
  EXPECT_NEAR(results[1].score, 0.5, 1e-6);
  EXPECT_NEAR(results[1].score, L1Score(query, b), 1e-6);
  database.Query(
      query, 3, [](EntryId entry) { return entry != 0; }, &results);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].entry, 1u);
  database.Query(query, 1, {}, &results);
  EXPECT_EQ(results.size(), 1u);
}

// The L1 score by hand for unequal weights, where only the |q - d| term tells a partial from a full match:
// q = (3/4, 1/4), d = (1/4, 3/4) over words 0 and 1; score = sum (q + d - |q - d|) / 2 = 1/4 + 1/4.
TEST(Database, L1ScoreCountsOnlyTheSharedPartOfEachWeight) {
  const std::vector<float> idf(4, 1.0f);
  BowVector entry, query, other;
  MakeBowVector({0, 1, 1, 1}, idf.data(), &entry);
  MakeBowVector({0, 0, 0, 1}, idf.data(), &query);
  MakeBowVector({2, 3}, idf.data(), &other);
  ASSERT_EQ(entry.weights, (std::vector<float>{0.25f, 0.75f}));
  Database database(4);
  database.Add(entry), database.Add(other);
  std::vector<QueryResult> results;
  database.Query(query, 3, {}, &results);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_NEAR(results[0].score, 0.5, 1e-6);
  EXPECT_NEAR(L1Score(query, entry), 0.5, 1e-6);
}

}  // namespace
}  // namespace patrolmap::vocab

#include <atomic>
#include <thread>

namespace patrolmap::vocab {
namespace {

// Three threads query while one adds 2,000 entries; every answer must be well formed, and a query
// for an entry already added when the query starts must find it with score 1.
TEST(Database, QueriesRunConcurrentlyWithAdds) {
  constexpr int kWords = 500, kEntries = 2000;
  const std::vector<float> idf(kWords, 1.0f);
  std::vector<BowVector> vectors(kEntries);
  std::mt19937 rng(11);
  std::uniform_int_distribution<WordId> word(0, kWords - 1);
  for (BowVector& bow : vectors) {
    std::vector<WordId> words(30);
    for (WordId& w : words) w = word(rng);
    MakeBowVector(words, idf.data(), &bow);
  }
  Database database(kWords);
  std::atomic<int> added{0};
  std::atomic<int> bad{0};
  std::thread writer([&] {
    for (const BowVector& bow : vectors) database.Add(bow), ++added;
  });
  std::vector<std::thread> readers;
  for (int r = 0; r < 3; ++r) {
    readers.emplace_back([&, r] {
      std::vector<QueryResult> results;
      for (int i = 0; i < 300; ++i) {
        const int known = added.load();
        if (known == 0) continue;
        const int target = (i * 7 + r) % known;
        database.Query(vectors[target], 3, {}, &results);
        const bool found = !results.empty() && results[0].score > 0.999;
        for (const QueryResult& q : results) bad += q.score > 1.0 || q.entry >= static_cast<EntryId>(kEntries);
        bad += !found;
      }
    });
  }
  writer.join();
  for (std::thread& reader : readers) reader.join();
  EXPECT_EQ(bad.load(), 0);
  EXPECT_EQ(database.size(), static_cast<std::size_t>(kEntries));
}

}  // namespace
}  // namespace patrolmap::vocab
