#include "patrolmap/vocab/database.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "patrolmap/core/status.h"

namespace patrolmap::vocab {

Database::Database(int word_count) : postings_(word_count) {}

EntryId Database::Add(const BowVector& bow) {
  std::unique_lock lock(mutex_);
  const auto id = static_cast<EntryId>(entries_.size());
  for (std::size_t i = 0; i < bow.words.size(); ++i) {
    PATROLMAP_CHECK(bow.words[i] < postings_.size());
    postings_[bow.words[i]].push_back({id, bow.weights[i]});
  }
  entries_.push_back(bow);
  return id;
}

void Database::Query(const BowVector& bow, int max_results, const std::function<bool(EntryId)>& allowed,
                     std::vector<QueryResult>* results) const {
  std::shared_lock lock(mutex_);
  results->clear();
  // For L1-normalised vectors, score = sum over common words of (q + d - |q - d|) / 2.
  std::vector<float> common(entries_.size(), 0.0f);
  std::vector<EntryId> touched;
  for (std::size_t i = 0; i < bow.words.size(); ++i) {
    if (bow.words[i] >= postings_.size()) continue;
    const float q = bow.weights[i];
    for (const Posting& posting : postings_[bow.words[i]]) {
      if (common[posting.entry] == 0.0f) touched.push_back(posting.entry);
      common[posting.entry] += q + posting.weight - std::abs(q - posting.weight);
    }
  }
  for (EntryId entry : touched) {
    if (!allowed || allowed(entry)) results->push_back({entry, std::min(1.0, 0.5 * common[entry])});
  }
  const auto better = [](const QueryResult& a, const QueryResult& b) {
    return a.score != b.score ? a.score > b.score : a.entry < b.entry;
  };
  const std::size_t keep = std::min<std::size_t>(results->size(), static_cast<std::size_t>(std::max(0, max_results)));
  std::partial_sort(results->begin(), results->begin() + keep, results->end(), better);
  results->resize(keep);
}

std::size_t Database::size() const {
  std::shared_lock lock(mutex_);
  return entries_.size();
}

BowVector Database::entry(EntryId id) const {
  std::shared_lock lock(mutex_);
  return entries_.at(id);
}

}  // namespace patrolmap::vocab
