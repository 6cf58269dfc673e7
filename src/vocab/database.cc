#include "patrolmap/vocab/database.h"

#include <algorithm>
#include <cmath>
#include <limits>
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
  check.InRange("place.query_min_skipped_postings", min_skipped_postings, 0, std::numeric_limits<int>::max());
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

void Database::ReadWords(const BowVector& bow, const QueryOptions& options, std::vector<std::uint32_t>* order) const {
  order->clear();
  for (std::uint32_t i = 0; i < bow.words.size(); ++i) {
    if (bow.words[i] < postings_.size()) order->push_back(i);
  }
  const int max_words = options.max_words;
  if (max_words <= 0 || order->size() <= static_cast<std::size_t>(max_words)) return;
  // A word can add at most its query weight to a score, and costs one read per posting: the words that buy the
  // most weight per read come first (the rare ones, and among them the ones the query holds most).
  const auto value = [&](std::uint32_t i) { return bow.weights[i] / (1.0 + postings_[bow.words[i]].size()); };
  std::nth_element(order->begin(), order->begin() + max_words, order->end(), [&](std::uint32_t a, std::uint32_t b) {
    const double va = value(a), vb = value(b);
    return va != vb ? va > vb : a < b;
  });
  std::size_t skipped = 0;
  for (auto i = order->begin() + max_words; i != order->end(); ++i) skipped += postings_[bow.words[*i]].size();
  if (skipped < static_cast<std::size_t>(options.min_skipped_postings)) {  // exhaustive is cheaper
    std::sort(order->begin(), order->end());
    return;
  }
  order->resize(max_words);
  std::sort(order->begin(), order->end());
}

namespace {

// Better first: the higher score, then the lower entry.
bool Better(const QueryResult& a, const QueryResult& b) {
  return a.score != b.score ? a.score > b.score : a.entry < b.entry;
}

// Keeps the `capacity` best results offered; `allowed` is asked only about the ones that would be kept.
class BestResults {
 public:
  BestResults(std::size_t capacity, const std::function<bool(EntryId)>& allowed, std::vector<QueryResult>* heap)
      : capacity_(capacity), allowed_(allowed), heap_(*heap) {
    heap_.clear();
  }

  void Offer(EntryId entry, float score) {
    const QueryResult result{entry, score};
    if (heap_.size() == capacity_ && (capacity_ == 0 || !Better(result, heap_.front()))) return;
    if (allowed_ && !allowed_(entry)) return;
    if (heap_.size() == capacity_) {
      std::pop_heap(heap_.begin(), heap_.end(), Better);
      heap_.back() = result;
    } else {
      heap_.push_back(result);
    }
    std::push_heap(heap_.begin(), heap_.end(), Better);
  }

  // The score an entry offered after all those kept must beat to be kept (0 while there is room).
  float floor() const {
    return heap_.size() == capacity_ && capacity_ > 0 ? static_cast<float>(heap_.front().score) : 0.0f;
  }

 private:
  std::size_t capacity_;
  const std::function<bool(EntryId)>& allowed_;
  std::vector<QueryResult>& heap_;
};

// Offers every entry with a sum to `best` and zeroes the sums again: the touched entries, or (dense) the whole
// array in ascending order, where an entry that only ties the worst one kept is never kept, so one comparison
// with that score skips the rest.
void OfferSums(bool dense, std::size_t count, const std::vector<EntryId>& touched, float* common, BestResults* best) {
  if (!dense) {
    for (const EntryId entry : touched) {
      best->Offer(entry, common[entry]);
      common[entry] = 0.0f;
    }
    return;
  }
  float floor = 0.0f;
  for (EntryId entry = 0; entry < count; ++entry) {
    if (common[entry] <= floor) continue;
    best->Offer(entry, common[entry]);
    floor = best->floor();
  }
  std::fill(common, common + count, 0.0f);
}

}  // namespace

void Database::AddPartialScores(const BowVector& bow, const std::vector<std::uint32_t>& order, bool dense,
                                float* common, std::vector<EntryId>* touched) const {
  for (const std::uint32_t i : order) {
    const float q = bow.weights[i];
    if (dense) {
      for (const Posting& posting : postings_[bow.words[i]]) {
        common[posting.entry] += q + posting.weight - std::abs(q - posting.weight);
      }
      continue;
    }
    for (const Posting& posting : postings_[bow.words[i]]) {
      if (common[posting.entry] == 0.0f) touched->push_back(posting.entry);
      common[posting.entry] += q + posting.weight - std::abs(q - posting.weight);
    }
  }
}

void Database::Query(const BowVector& bow, int max_results, const std::function<bool(EntryId)>& allowed,
                     std::vector<QueryResult>* results, const QueryOptions& options) const {
  std::shared_lock lock(mutex_);
  // For L1-normalised vectors, score = sum over common words of (q + d - |q - d|) / 2 = sum of min(q, d). The
  // sums live in a per-thread scratch array that only grows and is all zero between queries.
  thread_local std::vector<float> common;
  thread_local std::vector<EntryId> touched;
  thread_local std::vector<std::uint32_t> order;
  if (common.size() < entries_.size()) common.resize(entries_.size(), 0.0f);
  touched.clear();
  ReadWords(bow, options, &order);
  const bool two_stage = order.size() < bow.words.size();
  std::size_t reads = 0;
  for (const std::uint32_t i : order) reads += postings_[bow.words[i]].size();
  // Few reads: remember the entries touched. Many (a large share of the database): add without a branch and
  // sweep the whole array after. The sums, and so the results, are the same.
  const bool dense = reads > entries_.size() / 4;
  AddPartialScores(bow, order, dense, common.data(), &touched);
  const auto wanted = static_cast<std::size_t>(std::max(0, max_results));
  BestResults best(two_stage ? static_cast<std::size_t>(options.rescored) : wanted, allowed, results);
  OfferSums(dense, entries_.size(), touched, common.data(), &best);
  if (two_stage) {  // the best partial sums, scored exactly
    for (QueryResult& r : *results) r.score = Common(bow, r.entry);
  }
  for (QueryResult& r : *results) r.score = std::min(1.0, 0.5 * static_cast<float>(r.score));
  const std::size_t keep = std::min(results->size(), wanted);
  std::partial_sort(results->begin(), results->begin() + keep, results->end(), Better);
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
