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

class Database {
 public:
  explicit Database(int word_count);

  // Adds a vector; entries are numbered 0, 1, 2, ... in the order added.
  EntryId Add(const BowVector& bow);

  // The best `max_results` entries by L1 score, best first, among those for
  // which `allowed` is true (all when it is empty); entries sharing no word
  // with the query are never returned. Safe to call from several threads, also
  // while another thread adds.
  void Query(const BowVector& bow, int max_results, const std::function<bool(EntryId)>& allowed,
             std::vector<QueryResult>* results) const;

  std::size_t size() const;
  BowVector entry(EntryId id) const;

 private:
  struct Posting {
    EntryId entry;
    float weight;
  };
  std::vector<std::vector<Posting>> postings_;
  std::vector<BowVector> entries_;
  mutable std::shared_mutex mutex_;
};

}  // namespace patrolmap::vocab
