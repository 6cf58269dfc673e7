#include <cmath>

#include <gtest/gtest.h>

#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/eval/loop_closure_score.h"
#include "test_util.h"

namespace patrolmap::eval {
namespace {

KeyLocation Node(double t, ExtremumKind kind) {
  KeyLocation node;
  node.timestamp_ns = SecondsToNs(t);
  node.kind = kind;
  return node;
}

TruthEdge Edge(double t, bool opening) { return {SecondsToNs(t), 0, opening}; }

const auto kPeak = ExtremumKind::kPeak;
const auto kValley = ExtremumKind::kValley;

TEST(ExpectedSpans, InnerSpansAreRequiredOpenEndsOptional) {
  const std::vector<ExpectedSpan> spans = ExpectedSpans({Edge(10, true), Edge(20, false), Edge(30, true)}, 2.0);
  ASSERT_EQ(spans.size(), 4u);
  EXPECT_TRUE(std::isinf(spans[0].start_s));
  EXPECT_EQ(spans[0].kind, kPeak);  // facing a facade before the first opening
  EXPECT_FALSE(spans[0].required);
  EXPECT_EQ(spans[1].kind, kValley);
  EXPECT_TRUE(spans[1].required);
  EXPECT_EQ(spans[2].kind, kPeak);
  EXPECT_TRUE(spans[2].required);
  EXPECT_FALSE(spans[3].required);
}

TEST(ExpectedSpans, RunsOfOneKindCountOnce) {
  // opening 10, closing 20, closing 25 (a second step nearer), opening 30.
  const std::vector<ExpectedSpan> spans =
      ExpectedSpans({Edge(10, true), Edge(20, false), Edge(25, false), Edge(30, true)}, 2.0);
  ASSERT_EQ(spans.size(), 4u);
  EXPECT_DOUBLE_EQ(spans[2].start_s, 20.0);
  EXPECT_DOUBLE_EQ(spans[2].end_s, 30.0);
  EXPECT_EQ(spans[2].kind, kPeak);
}

TEST(ExpectedSpans, ASlitShorterThanTheMinimumJoinsItsNeighbours) {
  // Facade, a 1 s slit at 20-21 s, facade, a passage 30-40 s.
  const std::vector<TruthEdge> edges = {Edge(5, false), Edge(20, true), Edge(21, false), Edge(30, true), Edge(40, false)};
  const std::vector<ExpectedSpan> spans = ExpectedSpans(edges, 2.0);
  ASSERT_EQ(spans.size(), 4u);
  EXPECT_DOUBLE_EQ(spans[1].start_s, 5.0);  // one facade from 5 to 30 s
  EXPECT_DOUBLE_EQ(spans[1].end_s, 30.0);
  EXPECT_EQ(ExpectedSpans(edges, 0.5).size(), 6u);  // with a lower minimum the slit stays
}

TEST(ScoreKeyLocations, CountsTrueFalseAndMissed) {
  const std::vector<TruthEdge> edges = {Edge(10, true), Edge(20, false), Edge(30, true), Edge(40, false)};
  // Required: valley [10,20], peak [20,30], valley [30,40].
  const std::vector<KeyLocation> detected = {
      Node(15, kValley),   // true
      Node(16, kValley),   // second in the same span: false
      Node(25, kValley),   // wrong kind for a facade: false
      Node(40.8, kValley), // inside the tolerance of [30, 40]: true
      Node(50, kPeak),     // optional span after the last edge: true, never missed
  };
  const KeyLocationScore score = ScoreKeyLocations(detected, edges, {1.0, 2.0});
  EXPECT_EQ(score.detected, 5);
  EXPECT_EQ(score.expected, 3);
  EXPECT_EQ(score.true_positives, 3);
  EXPECT_EQ(score.false_positives, 2);
  EXPECT_EQ(score.missed, 1);  // the peak on [20, 30]
  EXPECT_DOUBLE_EQ(score.precision(), 0.6);
  EXPECT_NEAR(score.recall(), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(score.verdicts[1], Verdict::kFalsePositive);
  EXPECT_EQ(score.verdicts[2], Verdict::kFalsePositive);
}

TEST(ScoreKeyLocations, ToleranceDecidesAtTheSpanBorder) {
  const std::vector<TruthEdge> edges = {Edge(10, true), Edge(20, false)};
  EXPECT_EQ(ScoreKeyLocations({Node(21.5, kValley)}, edges, {1.0, 2.0}).true_positives, 0);
  EXPECT_EQ(ScoreKeyLocations({Node(21.5, kValley)}, edges, {2.0, 2.0}).true_positives, 1);
}

TEST(ScoreKeyLocations, NothingDetectedOnNoTruthIsPerfect) {
  const KeyLocationScore score = ScoreKeyLocations({}, {}, {});
  EXPECT_EQ(score.expected, 0);
  EXPECT_DOUBLE_EQ(score.precision(), 1.0);
  EXPECT_DOUBLE_EQ(score.recall(), 1.0);
}

TEST(ReadFiles, RunAndTruthTablesRoundTripAndBadLinesAreNamed) {
  testing::TempDir dir;
  testing::WriteText(dir / "run/key_locations.csv",
                     "node,timestamp_ns,frame_index,response,kind\n0,1500000000,45,0.031,valley\n");
  std::vector<KeyLocation> nodes;
  ASSERT_TRUE(ReadKeyLocationsCsv(dir / "run/key_locations.csv", &nodes).ok());
  ASSERT_EQ(nodes.size(), 1u);
  EXPECT_EQ(nodes[0].frame_index, 45);
  EXPECT_EQ(nodes[0].kind, kValley);
  testing::WriteText(dir / "run/key_locations.csv", "node,timestamp_ns,frame_index,response,kind\n0,15,45,0.1,top\n");
  const Status status = ReadKeyLocationsCsv(dir / "run/key_locations.csv", &nodes);
  EXPECT_NE(status.message().find("key_locations.csv:2: kind must be peak or valley"), std::string::npos);
  testing::WriteText(dir / "log/groundtruth/key_locations.csv", "#t,frame,kind\n100,3,opening\n200,6,closing\n");
  std::vector<TruthEdge> edges;
  ASSERT_TRUE(ReadTruthEdges(dir / "log", &edges).ok());
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_TRUE(edges[0].opening);
  EXPECT_EQ(ReadTruthEdges(dir / "nolog", &edges).code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace patrolmap::eval

namespace patrolmap::eval {
namespace {

NodeRecord NodeAt(int node, const char* flight, double t) { return {node, flight, SecondsToNs(t), node * 10}; }

TEST(ScoreLoopClosures, CountsPossibleFoundAndFalse) {
  const std::vector<NodeRecord> nodes = {
      NodeAt(0, "A", 0),  NodeAt(1, "A", 10), NodeAt(6, "A", 12), NodeAt(2, "A", 40),
      NodeAt(3, "A", 50), NodeAt(4, "B", 5),  NodeAt(5, "B", 30)};
  const std::vector<Place> places = {
      {0, 0, 0},       // 0
      {20, 0, 0},      // 1
      {20.2, 0, 0},    // 6: same place as 1 but 2 s later: a neighbour, not a loop closure
      {1, 1, 0.1},     // 2: back at 0 after 40 s: possible
      {20.5, 0, 2.0},  // 3: at 1's position looking elsewhere: not the same place
      {19, 1, 0.1},    // 4: flight B at 1's place: possible
      {100, 100, 0}};  // 5: nowhere seen before
  const std::vector<LoopClosureRecord> closures = {{2, 0}, {4, 1}, {5, 0}, {3, 1}};
  const LoopClosureScore score = ScoreLoopClosures(nodes, places, closures);
  EXPECT_EQ(score.nodes, 7);
  EXPECT_EQ(score.possible, 2);
  EXPECT_EQ(score.found, 2);
  EXPECT_EQ(score.reported, 4);
  EXPECT_EQ(score.true_positives, 2);
  EXPECT_EQ(score.false_positives, 2);
  EXPECT_DOUBLE_EQ(score.precision(), 0.5);
  EXPECT_DOUBLE_EQ(score.recall(), 1.0);
  EXPECT_EQ(score.correct, (std::vector<bool>{true, true, false, false}));
  LoopClosureScoreOptions wide;
  wide.max_heading_deg = 180.0;
  EXPECT_EQ(ScoreLoopClosures(nodes, places, closures, wide).true_positives, 3);  // 3 -> 1 now counts
}

TEST(ReadFiles, NodesClosuresAndPlaces) {
  testing::TempDir dir;
  testing::WriteText(dir / "nodes.csv", "node,flight,timestamp_ns,frame_index\n0,f1,100,3\n1,f2,200,7\n");
  testing::WriteText(dir / "loop_closures.csv",
                     "query_node,matched_node,query_frame,matched_frame,bow_score,matched_fraction,inliers\n1,0,7,3,0.4,0.6,80\n");
  testing::WriteText(dir / "log/groundtruth/places.csv", "#t,frame,x,y,z,yaw\n0,0,1,2,3,0.5\n33,1,2,2,3,0.5\n");
  std::vector<NodeRecord> nodes;
  std::vector<LoopClosureRecord> closures;
  std::vector<Place> places;
  ASSERT_TRUE(ReadNodesCsv(dir / "nodes.csv", &nodes).ok());
  ASSERT_TRUE(ReadLoopClosuresCsv(dir / "loop_closures.csv", &closures).ok());
  ASSERT_TRUE(ReadPlaces(dir / "log", &places).ok());
  EXPECT_EQ(nodes[1].flight, "f2");
  EXPECT_EQ(closures[0].matched_node, 0);
  EXPECT_DOUBLE_EQ(places[1].x, 2.0);
  testing::WriteText(dir / "log/groundtruth/places.csv", "0,0,1,2,3,0.5\n33,2,2,2,3,0.5\n");
  EXPECT_NE(ReadPlaces(dir / "log", &places).message().find("places.csv:2: frames must run"), std::string::npos);
  testing::WriteText(dir / "nodes.csv", "id,flight\n");
  EXPECT_NE(ReadNodesCsv(dir / "nodes.csv", &nodes).message().find("nodes.csv:1: header must start with 'node'"),
            std::string::npos);
}

}  // namespace
}  // namespace patrolmap::eval
