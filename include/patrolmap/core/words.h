// Numbers for messages and pages: with their nouns ("1 flight", "3 flights") or fixed decimals.
#pragma once

#include <cstdio>
#include <string>

namespace patrolmap {

inline std::string Counted(long long n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// A number with a fixed count of decimals: Fixed(2.345, 1) is "2.3".
inline std::string Fixed(double value, int decimals) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

}  // namespace patrolmap
