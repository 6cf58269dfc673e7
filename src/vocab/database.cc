#include "patrolmap/vocab/database.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "patrolmap/core/option_check.h"
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

bool QueryOptions::IsValid(std::string* error) const {
  OptionCheck check(error);
  check.InRange("place.query_words", max_words, 0, 1000000);
  check.InRange("place.rescored_entries", rescored, 1, 1000000);
  return check.ok();
}

float Database::Common(const BowVector& query, EntryId entry) const {
  const BowVector& d = entries_[entry];
  float common = 0.0f;
  std::size_t j = 0;
  for (std::size_t i = 0; i < query.words.size(); ++i) {
    while (j < d.words.size() && d.words[j] < query.words[i]) ++j;
    if (j == d.words.size()) break;
    if (d.words[j] != query.words[i]) continue;
    const float q = query.weights[i];
    common += q + d.weights[j] - std::abs(q - d.weights[j]);
  }
  return common;
}

void Database::ReadWords(const BowVector& bow, int max_words, std::vector<std::uint32_t>* order) const {
  order->clear();
  for (std::uint32_t i = 0; i < bow.words.size(); ++i) {
    if (bow.words[i] < postings_.size()) order->push_back(i);
  }
  if (max_words <= 0 || order->size() <= static_cast<std::size_t>(max_words)) return;
  std::nth_element(order->begin(), order->begin() + max_words, order->end(), [&](std::uint32_t a, std::uint32_t b) {
    const std::size_t la = postings_[bow.words[a]].size(), lb = postings_[bow.words[b]].size();
    return la != lb ? la < lb : a < b;
  });
  order->resize(max_words);
  std::sort(order->begin(), order->end());
}

void Database::Query(const BowVector& bow, int max_results, const std::function<bool(EntryId)>& allowed,
                     std::vector<QueryResult>* results, const QueryOptions& options) const {
  std::shared_lock lock(mutex_);
  results->clear();
  // For L1-normalised vectors, score = sum over common words of (q + d - |q - d|) / 2 = sum of min(q, d). The
  // sums live in a per-thread scratch array that only grows; the entries touched are zeroed again afterwards.
  thread_local std::vector<float> common;
  thread_local std::vector<EntryId> touched;
  thread_local std::vector<std::uint32_t> order;
  if (common.size() < entries_.size()) common.resize(entries_.size(), 0.0f);
  touched.clear();
  ReadWords(bow, options.max_words, &order);
  const bool two_stage = order.size() < bow.words.size();
  std::size_t reads = 0;
  for (const std::uint32_t i : order) reads += postings_[bow.words[i]].size();
  // Few reads: remember the entries touched. Many (a large share of the database): add without a branch and
  // sweep the whole array after. The sums, and so the results, are the same.
  const bool dense = reads > entries_.size() / 4;
  for (const std::uint32_t i : order) {
    const float q = bow.weights[i];
    if (dense) {
      for (const Posting& posting : postings_[bow.words[i]]) {
        common[posting.entry] += q + posting.weight - std::abs(q - posting.weight);
      }
      continue;
    }
    for (const Posting& posting : postings_[bow.words[i]]) {
      if (common[posting.entry] == 0.0f) touched.push_back(posting.entry);
      common[posting.entry] += q + posting.weight - std::abs(q - posting.weight);
    }
  }
  const auto collect = [&](EntryId entry) {
    if (!allowed || allowed(entry)) results->push_back({entry, common[entry]});
    common[entry] = 0.0f;
  };
  if (dense) {
    for (EntryId entry = 0; entry < entries_.size(); ++entry) {
      if (common[entry] != 0.0f) collect(entry);
    }
  } else {
    for (const EntryId entry : touched) collect(entry);
  }
  const auto better = [](const QueryResult& a, const QueryResult& b) {
    return a.score != b.score ? a.score > b.score : a.entry < b.entry;
  };
  if (two_stage) {  // the best partial sums, scored exactly
    const auto rescored = std::min(results->size(), static_cast<std::size_t>(options.rescored));
    std::nth_element(results->begin(), results->begin() + rescored, results->end(), better);
    results->resize(rescored);
    for (QueryResult& r : *results) r.score = Common(bow, r.entry);
  }
  for (QueryResult& r : *results) r.score = std::min(1.0, 0.5 * static_cast<float>(r.score));
  const std::size_t keep = std::min(results->size(), static_cast<std::size_t>(std::max(0, max_results)));
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
