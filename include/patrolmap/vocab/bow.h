// Bag-of-words vectors and their similarity (paper 002 §III-B; the L1 score of
// Nistér and Stewénius as DBoW2 uses it).
#pragma once

#include <cstdint>
#include <vector>

#include "patrolmap/core/key_frame_node.h"

namespace patrolmap::vocab {

using WordId = patrolmap::WordId;
using BowVector = patrolmap::BowVector;  // core/key_frame_node.h

// Similarity of two L1-normalised vectors: 1 - |a - b|_1 / 2, in [0, 1]; 1 for
// identical vectors, 0 for vectors without a common word.
double L1Score(const BowVector& a, const BowVector& b);

// Builds a BowVector from per-descriptor words and per-word weights (idf,
// indexed by word):
// term frequency times weight, L1-normalised; words with weight 0 are dropped.
void MakeBowVector(const std::vector<WordId>& descriptor_words, const float* word_weights, BowVector* bow);

}  // namespace patrolmap::vocab
