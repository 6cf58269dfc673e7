#include "patrolmap/io/natural_sort.h"

#include <algorithm>
#include <cctype>

namespace patrolmap::io {
namespace {

bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

// Compares the digit runs starting at a[i] and b[j] by value; advances i and j.
int CompareNumbers(std::string_view a, std::size_t* i, std::string_view b, std::size_t* j) {
  while (*i < a.size() && a[*i] == '0') ++*i;
  while (*j < b.size() && b[*j] == '0') ++*j;
  std::size_t a_end = *i, b_end = *j;
  while (a_end < a.size() && IsDigit(a[a_end])) ++a_end;
  while (b_end < b.size() && IsDigit(b[b_end])) ++b_end;
  const std::size_t a_length = a_end - *i, b_length = b_end - *j;
  int order = a_length < b_length ? -1 : (a_length > b_length ? 1 : 0);
  if (order == 0) order = a.substr(*i, a_length).compare(b.substr(*j, b_length));
  *i = a_end;
  *j = b_end;
  return order;
}

}  // namespace

bool NaturalLess(std::string_view a, std::string_view b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      const int order = CompareNumbers(a, &i, b, &j);
      if (order != 0) return order < 0;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i;
    ++j;
  }
  if ((a.size() - i) != (b.size() - j)) return (a.size() - i) < (b.size() - j);
  return a < b;  // equal by value ("01" vs "1"): fall back to plain order
}

void NaturalSort(std::vector<std::string>* names) {
  std::sort(names->begin(), names->end(), [](const std::string& a, const std::string& b) { return NaturalLess(a, b); });
}

}  // namespace patrolmap::io
