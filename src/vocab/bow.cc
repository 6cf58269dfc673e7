#include "patrolmap/vocab/bow.h"

#include <algorithm>
#include <cmath>

namespace patrolmap::vocab {

double L1Score(const BowVector& a, const BowVector& b) {
  // |a - b|_1 = 2 - sum over common words of (|a_i| + |b_i| - |a_i - b_i|) for L1-normalised vectors.
  double common = 0.0;
  std::size_t i = 0, j = 0;
  while (i < a.words.size() && j < b.words.size()) {
    if (a.words[i] < b.words[j]) {
      ++i;
    } else if (b.words[j] < a.words[i]) {
      ++j;
    } else {
      common += a.weights[i] + b.weights[j] - std::abs(a.weights[i] - b.weights[j]);
      ++i, ++j;
    }
  }
  return std::clamp(0.5 * common, 0.0, 1.0);
}

void MakeBowVector(const std::vector<WordId>& descriptor_words, const float* word_weights, BowVector* bow) {
  std::vector<WordId> sorted = descriptor_words;
  std::sort(sorted.begin(), sorted.end());
  bow->words.clear();
  bow->weights.clear();
  double total = 0.0;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t end = i;
    while (end < sorted.size() && sorted[end] == sorted[i]) ++end;
    const float weight = static_cast<float>(end - i) * word_weights[sorted[i]];
    if (weight > 0.0f) {
      bow->words.push_back(sorted[i]);
      bow->weights.push_back(weight);
      total += weight;
    }
    i = end;
  }
  for (float& weight : bow->weights) weight = static_cast<float>(weight / total);
}

}  // namespace patrolmap::vocab
