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
