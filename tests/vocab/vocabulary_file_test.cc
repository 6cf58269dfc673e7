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

using testing_fixtures::TrainOnBlobs;

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

}  // namespace
}  // namespace patrolmap::vocab
