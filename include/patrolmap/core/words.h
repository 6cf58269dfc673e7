// Numbers with their nouns, for messages and pages: "1 flight", "3 flights".
#pragma once

#include <string>

namespace patrolmap {

inline std::string Counted(long long n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace patrolmap
