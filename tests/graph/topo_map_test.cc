#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "patrolmap/core/checksum.h"

#include "graph/fixtures.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/layout.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/graph/topo_map.h"
#include "recompute_checksums.h"
#include "sample_map.h"
#include "test_util.h"

namespace patrolmap::graph {
namespace {

using testing::TwoFlights;

TEST(TopoMap, QueriesUsersNeed) {
  const TopoMap map = TwoFlights();
  EXPECT_EQ(map.node_count(), 7);
  EXPECT_EQ(map.edge_count(), 8);  // 3 + 2 traversals, 3 loop closures
  EXPECT_EQ(map.loop_closure_count(), 3);
  EXPECT_EQ(map.Neighbours(1), (std::vector<int>{0, 2, 4, 5}));
  EXPECT_EQ(map.NodesOfPlace(4), (std::vector<int>{1, 4, 5}));
  EXPECT_EQ(map.NodesOfPlace(0), (std::vector<int>{0}));
  EXPECT_EQ(map.Path(0, 6), (std::vector<int>{0, 1, 5, 6}));  // over the loop closure 1~5: 3 edges, not 4
  EXPECT_EQ(map.Path(2, 2), (std::vector<int>{2}));
  EXPECT_EQ(map.Flights(), (std::vector<std::string>{"a", "b"}));
  TopoMap split;
  split.AddNode({});
  split.AddNode({});
  EXPECT_TRUE(split.Path(0, 1).empty());
}

// A log too short for a key location leaves a flight with a patrol record and no node: it is still a flight, in the
// order flown (after the flight recorded before it), so a patrol can compare against it or be compared.
TEST(TopoMap, AFlightWithARecordButNoNodeIsListedInTheOrderFlown) {
  TopoMap map = TwoFlights();  // records: b
  PatrolRecord late;
  late.flight = "c";
  map.SetPatrol(late);
  EXPECT_EQ(map.Flights(), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(map.FlightSpan("a"), std::make_pair(SecondsToNs(0.0), SecondsToNs(30.0)));  // nodes 0-3
  EXPECT_FALSE(map.FlightSpan("c"));                                                    // neither nodes nor frames
  late.route.resize(2);
  late.route[0].timestamp_ns = SecondsToNs(95.0);
  late.route[1].timestamp_ns = SecondsToNs(99.0);
  map.SetPatrol(late);
  EXPECT_EQ(map.FlightSpan("c"), std::make_pair(SecondsToNs(95.0), SecondsToNs(99.0)));
  TopoMap early;
  for (const char* flight : {"x", "y"}) {
    PatrolRecord record;
    record.flight = flight;
    early.SetPatrol(record);
  }
  KeyFrameNode node;
  node.flight = "z";
  early.AddNode(node);
  PatrolRecord z;
  z.flight = "z";
  early.SetPatrol(z);
  PatrolRecord after_z;
  after_z.flight = "w";
  early.SetPatrol(after_z);
  // x and y were recorded before z's record, w after it.
  EXPECT_EQ(early.Flights(), (std::vector<std::string>{"x", "y", "z", "w"}));
  TopoMap ordered = TwoFlights();  // b's record comes first, then a's: m goes after a
  for (const char* flight : {"a", "m"}) {
    PatrolRecord record;
    record.flight = flight;
    ordered.SetPatrol(record);
  }
  EXPECT_EQ(ordered.Flights(), (std::vector<std::string>{"a", "m", "b"}));
}

TEST(TopoMapDeathTest, LoopClosureOntoItselfAborts) {
  TopoMap map = TwoFlights();
  EXPECT_DEATH(map.AddEdge(2, 2, {EdgeKind::kLoopClosure, 0, 0, 0}), "check failed");
}

}  // namespace
}  // namespace patrolmap::graph
