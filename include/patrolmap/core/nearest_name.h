// The known name nearest a mistyped one, for messages that suggest it: "unknown key 'flow.smothing'; did you mean
// 'flow.smoothing'?".
#pragma once

#include <string>
#include <vector>

namespace patrolmap {

// Edits (insertions, deletions, substitutions, swaps of neighbours) that turn `a` into `b` (Damerau-Levenshtein,
// optimal string alignment).
std::size_t EditDistance(const std::string& a, const std::string& b);

// The name of `names` fewest edits from `word`, when it is close enough to be the one meant (at most a third of
// the word's length, and at least two edits allowed); "" otherwise. Ties go to the first.
std::string NearestName(const std::string& word, const std::vector<std::string>& names);

// "; did you mean 'NAME'?" for NearestName, or "".
std::string DidYouMean(const std::string& word, const std::vector<std::string>& names);

}  // namespace patrolmap
