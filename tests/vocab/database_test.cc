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

// The two-stage query reads first the words that buy the most query weight per posting read: a word the query
// holds twenty times beats a rarer word it holds once. And `allowed` is applied before the entries to rescore
// are chosen, so excluded entries never take their places.
TEST(Database, TwoStageQueryReadsTheWordsWithMostWeightPerPosting) {
  const std::vector<float> idf(4, 1.0f);
  Database database(4);
  BowVector bow;
  for (int e = 0; e < 50; ++e) {
    MakeBowVector(e < 2 ? std::vector<WordId>{0, 1, 2, 3} : std::vector<WordId>{0}, idf.data(), &bow);
    database.Add(bow);  // entries 2..49 hold word 0 only
  }
  BowVector query;
  MakeBowVector({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}, idf.data(), &query);
  QueryOptions options;
  options.max_words = 1;
  options.rescored = 1;
  options.min_skipped_postings = 0;
  std::vector<QueryResult> results;
  database.Query(query, 3, {}, &results, options);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].entry, 2u);  // from word 0's list; the rarest word (1) would give entry 0 or 1
  EXPECT_NEAR(results[0].score, L1Score(query, database.entry(2)), 1e-6);
  database.Query(
      query, 3, [](EntryId entry) { return entry > 40; }, &results, options);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].entry, 41u);
}

// The two-stage query (QueryOptions::max_words): with all the query's words it is the exhaustive query; with a
// few rare words it still finds an entry that shares them, with the exhaustive score bit for bit; and the entries
// it rescores are the best partial scores only.
TEST(Database, TwoStageQueryScoresTheEntriesOfTheRarestWordsExactly) {
  constexpr int kWords = 200;
  std::vector<float> idf(kWords);
  for (int w = 0; w < kWords; ++w) idf[w] = 0.5f + 0.02f * w;
  std::mt19937 rng(3);
  std::uniform_int_distribution<WordId> common(0, 19), rare(20, kWords - 1);
  Database database(kWords);
  std::vector<BowVector> entries;
  for (int e = 0; e < 300; ++e) {
    std::vector<WordId> words;
    for (int i = 0; i < 40; ++i) words.push_back(i % 4 == 0 ? rare(rng) : common(rng));
    BowVector bow;
    MakeBowVector(words, idf.data(), &bow);
    database.Add(bow);
    entries.push_back(bow);
  }
  std::vector<QueryResult> exact, two_stage;
  QueryOptions exhaustive;
  exhaustive.max_words = 0;
  for (const EntryId target : {7u, 150u, 299u}) {
    database.Query(entries[target], 3, {}, &exact, exhaustive);
    QueryOptions all;
    all.max_words = static_cast<int>(entries[target].words.size());
    all.min_skipped_postings = 0;
    database.Query(entries[target], 3, {}, &two_stage, all);
    ASSERT_EQ(two_stage.size(), exact.size());
    for (std::size_t i = 0; i < exact.size(); ++i) {
      EXPECT_EQ(two_stage[i].entry, exact[i].entry);
      EXPECT_EQ(two_stage[i].score, exact[i].score);
    }
    QueryOptions rarest;
    rarest.max_words = 5;
    rarest.rescored = 10;
    rarest.min_skipped_postings = 0;
    database.Query(entries[target], 3, {}, &two_stage, rarest);
    ASSERT_FALSE(two_stage.empty());
    EXPECT_EQ(two_stage[0].entry, target);  // an entry is its own best match
    EXPECT_EQ(two_stage[0].score, exact[0].score);
    rarest.rescored = 1;
    database.Query(entries[target], 3, {}, &two_stage, rarest);
    EXPECT_EQ(two_stage.size(), 1u);
    // The lists it would skip hold fewer postings than min_skipped_postings: the query is exhaustive.
    rarest.min_skipped_postings = 100000;
    database.Query(entries[target], 3, {}, &two_stage, rarest);
    ASSERT_EQ(two_stage.size(), exact.size());
    for (std::size_t i = 0; i < exact.size(); ++i) EXPECT_EQ(two_stage[i].entry, exact[i].entry);
  }
  // A query that reads few postings (one rare word: the entries touched are remembered) and one that reads
  // many (every entry: the array is swept) both rank as the L1 score by brute force.
  for (const std::vector<WordId>& words : {std::vector<WordId>{150}, std::vector<WordId>{0, 1, 2, 3, 150}}) {
    BowVector query;
    MakeBowVector(words, idf.data(), &query);
    std::vector<QueryResult> brute;
    for (EntryId e = 0; e < entries.size(); ++e) {
      const double score = L1Score(query, entries[e]);
      if (score > 0.0) brute.push_back({e, score});
    }
    std::stable_sort(brute.begin(), brute.end(),
                     [](const QueryResult& a, const QueryResult& b) { return a.score > b.score + 1e-6; });
    database.Query(query, 1000, {}, &exact);
    ASSERT_EQ(exact.size(), brute.size()) << words.size() << " words";
    for (std::size_t i = 0; i < exact.size(); ++i) EXPECT_NEAR(exact[i].score, brute[i].score, 1e-6);
  }
  std::string error;
  QueryOptions bad;
  bad.rescored = 0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("place.rescored_entries"), std::string::npos) << error;
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
