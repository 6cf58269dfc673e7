// Test inputs shared by the graph stage's test files.
#ifndef PATROLMAP_TESTS_GRAPH_FIXTURES_H_
#define PATROLMAP_TESTS_GRAPH_FIXTURES_H_

#include <cstddef>
#include <string>

namespace patrolmap::graph::testing_fixtures {

// How often `what` occurs in `text`.
inline std::size_t CountOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace patrolmap::graph::testing_fixtures

#endif  // PATROLMAP_TESTS_GRAPH_FIXTURES_H_
