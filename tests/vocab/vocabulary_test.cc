#include <atomic>
#include <thread>

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
#include "vocab/fixtures.h"

namespace patrolmap::vocab {
namespace {

using testing_fixtures::Blobs;
using testing_fixtures::TrainOnBlobs;

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

}  // namespace
}  // namespace patrolmap::vocab

namespace patrolmap::vocab {
namespace {

// The words of the shipped vocabulary for 4,000 RootSIFT-like descriptors (cv::RNG, the same on every machine),
// folded into one number: a faster Quantize must give the same words, and a map built before it must
// still be matched as it was built.
TEST(Vocabulary, ShippedVocabularyGivesTheSameWords) {
  Vocabulary vocabulary;
  ASSERT_TRUE(Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &vocabulary).ok());
  cv::Mat descriptors(4000, 128, CV_32F);
  cv::RNG rng(12345);
  rng.fill(descriptors, cv::RNG::UNIFORM, 0.0, 1.0);
  for (int row = 0; row < descriptors.rows; ++row) {
    float* d = descriptors.ptr<float>(row);
    for (int i = 0; i < 128; ++i) d[i] = d[i] * d[i] * d[i] * d[i];  // a few strong bins, as SIFT has
    const double sum = cv::sum(descriptors.row(row))[0];
    for (int i = 0; i < 128; ++i) d[i] = static_cast<float>(std::sqrt(d[i] / sum));
  }
  std::vector<WordId> words;
  vocabulary.Quantize(descriptors, &words);
  std::uint64_t fold = 1469598103934665603ull;  // FNV-1a over the word ids
  for (const WordId w : words) fold = (fold ^ w) * 1099511628211ull;
  std::set<WordId> distinct(words.begin(), words.end());
  EXPECT_GT(distinct.size(), 200u);         // the descriptors spread over the vocabulary
  EXPECT_EQ(fold, 9498965974220549256ull);  // the vocabulary scripts/build_vocabulary.sh builds
}

}  // namespace
}  // namespace patrolmap::vocab
