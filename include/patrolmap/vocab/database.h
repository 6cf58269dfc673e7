// An image database over bag-of-words vectors with an inverted index: per word
// a contiguous posting list of (entry, weight), so a query touches only the
// entries that share a word with it (paper 002 §III-B, "DB query").
#pragma once

#include <cstdint>
#include <functional>
#include <shared_mutex>
#include <vector>

#include "patrolmap/vocab/bow.h"

namespace patrolmap::vocab {

using EntryId = std::uint32_t;

struct QueryResult {
  EntryId entry = 0;
  double score = 0.0;  // L1Score with the query, in [0, 1]
};

// How much of the inverted index a query reads. Exhaustive (max_words 0) scores every entry that shares a word
// with the query. Two-stage (max_words > 0): only the posting lists of the query's max_words words that hold the
// most query weight per posting (a word adds at most its query weight to a score; the rare words, and among them
// the ones the query holds most) are read, and the `rescored` entries with the best partial scores are scored
// exactly (the exhaustive score, bit for bit). The result equals the exhaustive one whenever its entries are
// among those. A query whose skipped lists would hold fewer than min_skipped_postings postings is exhaustive:
// on small databases that is faster than rescoring (BENCHMARKS.md, "Fleet scale", measures both).
struct QueryOptions {
  int max_words = 64;                 // 0: exhaustive
  int rescored = 100;                 // entries scored exactly after the first stage
  int min_skipped_postings = 100000;  // two-stage only when it skips at least this many postings

  bool IsValid(std::string* error) const;
};

class Database {
 public:
  explicit Database(int word_count);

  // Adds a vector; entries are numbered 0, 1, 2, ... in the order added.
  EntryId Add(const BowVector& bow);

  // The best `max_results` entries by L1 score, best first (ties: lower id first), among those for which
  // `allowed` is true (all when it is empty); entries sharing no word with the query are never returned. Safe
  // to call from several threads, also while another thread adds.
  void Query(const BowVector& bow, int max_results, const std::function<bool(EntryId)>& allowed,
             std::vector<QueryResult>* results, const QueryOptions& options = QueryOptions{}) const;

  std::size_t size() const;
  BowVector entry(EntryId id) const;

 private:
  struct Posting {
    EntryId entry;
    float weight;
  };
  // The exact score of `entry`, as the exhaustive pass sums it (in float, in the query's word order).
  float Common(const BowVector& query, EntryId entry) const;
  // The query's words whose lists are read (indices into `bow`, ascending): all, or the max_words that hold the
  // most query weight per posting when the others hold at least min_skipped_postings.
  void ReadWords(const BowVector& bow, const QueryOptions& options, std::vector<std::uint32_t>* order) const;

  // Adds each read word's share to the sums of the entries in its list; `touched` notes the entries whose
  // sum was zero (unless `dense`).
  void AddPartialScores(const BowVector& bow, const std::vector<std::uint32_t>& order, bool dense, float* common,
                        std::vector<EntryId>* touched) const;

  std::vector<std::vector<Posting>> postings_;
  std::vector<BowVector> entries_;
  mutable std::shared_mutex mutex_;
};

}  // namespace patrolmap::vocab
