#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "patrolmap/eval/change_score.h"
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
  const std::vector<TruthEdge> edges = {Edge(5, false), Edge(20, true), Edge(21, false), Edge(30, true),
                                        Edge(40, false)};
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
      Node(15, kValley),    // true
      Node(16, kValley),    // second in the same span: false
      Node(25, kValley),    // wrong kind for a facade: false
      Node(40.8, kValley),  // inside the tolerance of [30, 40]: true
      Node(50, kPeak),      // optional span after the last edge: true, never missed
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
  const std::vector<NodeRecord> nodes = {NodeAt(0, "A", 0),  NodeAt(1, "A", 10), NodeAt(6, "A", 12), NodeAt(2, "A", 40),
                                         NodeAt(3, "A", 50), NodeAt(4, "B", 5),  NodeAt(5, "B", 30)};
  const std::vector<Place> places = {{0, 0, 0},     // 0
                                     {20, 0, 0},    // 1
                                     {20.2, 0, 0},  // 6: same place as 1 but 2 s later: a neighbour, not a loop closure
                                     {1, 1, 0.1},   // 2: back at 0 after 40 s: possible
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
  testing::WriteText(
      dir / "loop_closures.csv",
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

TruthObject Truth(int id, const char* label, double x, double y, int detections) {
  TruthObject o;
  o.id = id, o.label = label, o.centre = Eigen::Vector2d(x, y);
  o.length = o.width = o.height = 1.0;
  o.detections = detections;
  return o;
}

TEST(ChangeScore, ObjectStatesPerStateWithOptionalSightings) {
  const std::vector<TruthObject> before = {Truth(1, "crate", 0, 0, 10), Truth(2, "crate", 5, 0, 10),
                                           Truth(3, "barrel", 9, 0, 10), Truth(4, "crate", 20, 0, 1),
                                           Truth(6, "vehicle", 30, 0, 9)};
  const std::vector<TruthObject> after = {Truth(1, "crate", 0, 0, 10), Truth(2, "crate", 8, 0, 10),
                                          Truth(4, "crate", 20, 0, 12), Truth(5, "crate", 12, 0, 10),
                                          Truth(6, "vehicle", 34, 0, 1)};
  // 1 persistent, 2 moved, 3 removed, 4 stayed but seen once before (optional), 5 new, 6 moved out of sight
  // after (removed as a patrol can know it).
  const auto at = [](double x) { return Eigen::Vector3d(x, 0.1, 0.5); };
  const std::vector<ReportedObject> reported = {
      {"persistent", "crate", at(0), at(0)}, {"moved", "crate", at(5), at(8.3)}, {"removed", "barrel", at(9), {}},
      {"new", "crate", {}, at(20.2)},        {"new", "crate", {}, at(12)},       {"removed", "vehicle", at(30), {}},
      {"new", "barrel", {}, at(40)},         {"unobserved", "crate", at(50), {}}};
  const ObjectChangeScore score = ScoreObjectChanges(reported, before, after, ChangeScoreOptions{});
  EXPECT_EQ(score.by_state.at("persistent").true_positives, 1);
  EXPECT_EQ(score.by_state.at("moved").true_positives, 1);
  EXPECT_EQ(score.by_state.at("removed").true_positives, 2);
  EXPECT_EQ(score.by_state.at("removed").false_negatives, 0);
  const Counts& fresh = score.by_state.at("new");
  EXPECT_EQ(fresh.true_positives, 1);   // object 5
  EXPECT_EQ(fresh.false_positives, 1);  // the barrel at 40 m; object 4 reported new is optional, no error
  EXPECT_EQ(fresh.false_negatives, 0);
  EXPECT_DOUBLE_EQ(fresh.Precision(), 0.5);
  EXPECT_NEAR(fresh.F1(), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(score.unobserved, 1);
  // Each required true change found or missed, each false report, with the report's index.
  const auto outcome = [&score](const char* state, const char* what) {
    std::vector<int> reports;
    for (const ObjectOutcome& o : score.outcomes) {
      if (o.state == state && o.outcome == what) reports.push_back(o.reported);
    }
    return reports;
  };
  EXPECT_EQ(outcome("new", "found"), std::vector<int>({4}));
  EXPECT_EQ(outcome("new", "false"), std::vector<int>({6}));  // the optional object 4's report is neither
  EXPECT_EQ(outcome("removed", "found"), std::vector<int>({2, 5}));
  EXPECT_TRUE(outcome("removed", "missed").empty());
  EXPECT_EQ(score.outcomes.size(), 6u);  // 1 persistent, 1 moved, 2 removed, 1 new found and 1 false
  // A label that disagrees or a position 1 m off is no hit.
  const ObjectChangeScore wrong = ScoreObjectChanges({{"removed", "crate", at(9), {}}, {"new", "crate", {}, at(13.2)}},
                                                     before, after, ChangeScoreOptions{});
  EXPECT_EQ(wrong.by_state.at("removed").true_positives, 0);
  EXPECT_EQ(wrong.by_state.at("new").false_positives, 1);
  ASSERT_EQ(wrong.outcomes.size(),
            7u);  // by state: 1 missed; 5 missed, a false new; 3 and 6 missed, a false removal; 2 missed
  const ObjectOutcome& missed_barrel = wrong.outcomes[3];
  EXPECT_EQ(missed_barrel.outcome, "missed");
  EXPECT_EQ(missed_barrel.label, "barrel");
  EXPECT_EQ(missed_barrel.reported, -1);
  EXPECT_EQ(missed_barrel.id, 3);  // the true object's id; a false report has none
  EXPECT_EQ(wrong.outcomes[2].outcome, "false");
  EXPECT_EQ(wrong.outcomes[2].id, -1);
  ASSERT_TRUE(missed_barrel.before.has_value());
  EXPECT_DOUBLE_EQ(missed_barrel.before->x(), 9.0);
}

// A class-agnostic object (from changed geometry) matches a true object of any label, and a change the detector
// saw too rarely to count is optional for it, never for a detected one.
TEST(ChangeScore, ClassAgnosticObjectsMatchAnyLabelAndWhatTheDetectorMissed) {
  const std::vector<TruthObject> before = {Truth(1, "barrel", 0, 0, 10), Truth(2, "crate", 10, 0, 0)};
  const std::vector<TruthObject> after = {Truth(3, "vehicle", 20, 0, 10), Truth(4, "crate", 30, 0, 1)};
  const auto at = [](double x) { return Eigen::Vector3d(x, 0.2, 0.5); };
  std::vector<ReportedObject> reported = {{"removed", "object", at(0), {}, true},
                                          {"removed", "object", at(10), {}, true},
                                          {"new", "object", {}, at(20), true},
                                          {"new", "object", {}, at(30), true},
                                          {"new", "object", {}, at(40), true}};
  ObjectChangeScore score = ScoreObjectChanges(reported, before, after, ChangeScoreOptions{});
  EXPECT_EQ(score.by_state.at("removed").true_positives, 1);   // the barrel
  EXPECT_EQ(score.by_state.at("removed").false_positives, 0);  // the unseen crate: optional
  EXPECT_EQ(score.by_state.at("new").true_positives, 1);       // the vehicle
  EXPECT_EQ(score.by_state.at("new").false_positives, 1);      // at 40 m: nothing there; at 30 m optional
  EXPECT_EQ(score.by_state.at("new").false_negatives, 0);
  // On the object's footprint (1 x 1 m) but 1.2 m from its centre: a hit for a class-agnostic object.
  reported[2].after = Eigen::Vector3d(20.0, 1.2, 0.5);
  EXPECT_EQ(ScoreObjectChanges(reported, before, after, ChangeScoreOptions{}).by_state.at("new").true_positives, 1);
  reported[2].after = Eigen::Vector3d(20.0, 1.6, 0.5);  // 1.1 m off the footprint
  EXPECT_EQ(ScoreObjectChanges(reported, before, after, ChangeScoreOptions{}).by_state.at("new").true_positives, 0);
  reported[2].after = at(20);
  // The same reports from a detector: the label must agree and the unseen changes count against it.
  for (ReportedObject& r : reported) r.class_agnostic = false;
  score = ScoreObjectChanges(reported, before, after, ChangeScoreOptions{});
  EXPECT_EQ(score.by_state.at("removed").true_positives, 0);
  EXPECT_EQ(score.by_state.at("removed").false_positives, 2);
  EXPECT_EQ(score.by_state.at("new").false_positives, 3);
  EXPECT_EQ(score.by_state.at("new").false_negatives, 1);
}

TEST(ChangeScore, GeometryCoreBandAndUnobservedVoxels) {
  // One 1 m crate (centre (1, 1), z 0..1) removed between the flights; 0.2 m voxels.
  const std::vector<TruthObject> before = {Truth(1, "crate", 1.0, 1.0, 10)};
  const std::vector<TruthObject> after;
  EvidenceGridData a, b;
  a.voxel_size = b.voxel_size = 0.2;
  const auto add = [](EvidenceGridData* g, int x, int y, int z, int hits, int passes) {
    g->voxels.push_back({x, y, z, static_cast<std::uint16_t>(hits), static_cast<std::uint16_t>(passes)});
  };
  add(&a, 4, 5, 2, 9, 0), add(&b, 4, 5, 2, 0, 9);  // inside the crate's face: core, reported
  add(&a, 5, 5, 2, 9, 0), add(&b, 5, 5, 2, 0, 9);  // core, missed
  add(&a, 7, 5, 2, 5, 5), add(&b, 7, 5, 2, 0, 9);  // centre 1.4: 0.1 m outside the face, band, reported
  add(&a, 9, 5, 2, 0, 9), add(&b, 9, 5, 2, 0, 9);  // free in both, reported: false
  add(&a, 12, 5, 2, 9, 0);                         // not observed in the second flight: never counted
  const std::vector<Eigen::Vector3i> changed = {{4, 5, 2}, {7, 5, 2}, {9, 5, 2}, {12, 5, 2}};
  const GeometryScore score = ScoreGeometry(changed, a, b, before, after, ChangeScoreOptions{});
  EXPECT_EQ(score.observed_voxels, 4);
  EXPECT_EQ(score.voxels.true_positives, 2);
  EXPECT_EQ(score.voxels.false_positives, 1);
  EXPECT_EQ(score.voxels.false_negatives, 1);
  EXPECT_DOUBLE_EQ(score.Iou(), 0.5);
}

// A false voxel beside a changed object is a true change reported too wide; beside an object that stayed, or away
// from every object, it is a change where there was none.
TEST(ChangeScore, FalseVoxelsNearAChangedObjectAreCountedApart) {
  // A 1 m crate (centre (1, 1), z 0..1) removed, and one at (5, 1) that stayed; 0.2 m voxels.
  const std::vector<TruthObject> before = {Truth(1, "crate", 1.0, 1.0, 10), Truth(2, "crate", 5.0, 1.0, 10)};
  const std::vector<TruthObject> after = {Truth(2, "crate", 5.0, 1.0, 10)};
  EvidenceGridData a, b;
  a.voxel_size = b.voxel_size = 0.2;
  // Centres: (1.8, 1, 0.4) 0.3 m beyond the removed crate's face (at x 1.5); (1, 1, 1.2) 0.2 m above its top;
  // (2.8, 1, 0.4) 1.3 m from it and 1.7 m from the other; (4.4, 1, 0.4) 0.1 m from the face of the crate that stayed.
  const std::vector<Eigen::Vector3i> changed = {{9, 5, 2}, {5, 5, 6}, {14, 5, 2}, {22, 5, 2}};
  for (const Eigen::Vector3i& v : changed) {  // each observed free in both flights: every one reported is false
    a.voxels.push_back({v.x(), v.y(), v.z(), 0, 9});
    b.voxels.push_back({v.x(), v.y(), v.z(), 0, 9});
  }
  std::sort(a.voxels.begin(), a.voxels.end(), VoxelBefore);
  std::sort(b.voxels.begin(), b.voxels.end(), VoxelBefore);
  const GeometryScore score = ScoreGeometry(changed, a, b, before, after, ChangeScoreOptions{});
  EXPECT_EQ(score.voxels.false_positives, 4);
  EXPECT_EQ(score.false_near_change, 2);
  ChangeScoreOptions tight;
  tight.near_change_m = 0.25;
  EXPECT_EQ(ScoreGeometry(changed, a, b, before, after, tight).false_near_change, 1);
}

// A voxel touches a turned box when the two share a point: for a crate turned by 45 degrees a 0.2 m voxel reaches
// 0.141 m towards a face (not 0.1), and the crate's corner reaches into a voxel beside it.
TEST(ChangeScore, AVoxelTouchesATurnedBoxWhereTheyShareAPoint) {
  TruthObject crate = Truth(1, "crate", 0, 0, 10);
  crate.yaw = M_PI / 4;
  const Eigen::Vector3d normal(std::cos(M_PI / 4), std::sin(M_PI / 4), 0);  // the face's outward normal
  const Eigen::Vector3d mid(0, 0, 0.5);
  EXPECT_TRUE(crate.Touches(mid + normal * 0.63, 0.1));  // 0.13 m off the face
  EXPECT_FALSE(crate.Contains(mid + normal * 0.63, 0.1));
  EXPECT_FALSE(crate.Touches(mid + normal * 0.65, 0.1));  // 0.15 m off: beyond the voxel's reach
  const double corner = std::sqrt(0.5);                   // the corner on the x axis
  EXPECT_TRUE(crate.Touches({corner + 0.09, 0, 0.5}, 0.1));
  EXPECT_FALSE(crate.Touches({corner + 0.11, 0, 0.5}, 0.1));  // inside the reach along the faces' normals, yet apart
  EXPECT_FALSE(crate.Touches({0, 0, 1.11}, 0.1));             // above the top
  // Wholly inside: the voxel's reach from every face.
  EXPECT_TRUE(crate.Encloses({0, 0, 0.5}, 0.1));
  EXPECT_TRUE(crate.Encloses(mid + normal * 0.35, 0.1));
  EXPECT_FALSE(crate.Encloses(mid + normal * 0.37, 0.1));
  EXPECT_FALSE(crate.Encloses({0, 0, 0.95}, 0.1));
}

TEST(ChangeScore, AppearanceRegionsOnVisibleObjectChanges) {
  // A camera at the origin looking along +x (camera z forward = world x, x right = world -y, y down = -z).
  CameraPoseSample pose;
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0), r.col(1) = Eigen::Vector3d(0, 0, -1), r.col(2) = Eigen::Vector3d(1, 0, 0);
  pose.rotation = Eigen::Quaterniond(r);
  pose.position = Eigen::Vector3d(0, 0, 0.5);
  const CameraIntrinsics camera{100, 100, 80, 50, 160, 100};
  std::vector<TruthObject> before = {Truth(1, "crate", 10, 0, 10), Truth(2, "crate", 10, 3, 10),
                                     Truth(3, "crate", 10, -3, 10), Truth(4, "crate", -10, 0, 10)};
  std::vector<TruthObject> after = {Truth(1, "crate", 10, 0, 10), Truth(3, "crate", 12, -3, 10),
                                    Truth(5, "crate", 8, 2, 10)};
  for (auto* objects : {&before, &after}) {
    for (TruthObject& o : *objects) o.seen_ns = {1'000'000'000};
  }
  after[2].seen_ns = {2'000'000'000};  // the new crate 5 was not seen near the key frame: not visible there
  ChangeScoreOptions options;
  options.min_area_px = 20;
  // Before: 2 (removed) and 3 (moved away) are changes, 1 stayed, 4 is behind the camera.
  const std::vector<cv::Rect2d> prior = VisibleChangeBoxes(before, after, 1'000'000'000, pose, camera, options);
  ASSERT_EQ(prior.size(), 2u);
  EXPECT_NEAR(prior[0].x + prior[0].width / 2, 80 - 100 * 3.0 / 10, 3);  // world +y is image left
  EXPECT_NEAR(prior[0].width, 100 * (3.5 / 9.5 - 2.5 / 10.5), 1e-6);     // from its near left to its far right edge
  const std::vector<cv::Rect2d> current = VisibleChangeBoxes(after, before, 1'000'000'000, pose, camera, options);
  ASSERT_EQ(current.size(), 1u);  // crate 3 at its new place
  // One region on crate 2's old place, one on crate 3's new place, one on the unchanged crate 1.
  const RegionBoxes on_two{prior[0], prior[0]}, on_three{cv::Rect2d(0, 0, 1, 1), current[0]};
  const cv::Rect2d centre(75, 45, 10, 10);
  const AppearanceScore score = ScoreAppearance({{prior, current}}, {{on_two, on_three, {centre, centre}}}, options);
  EXPECT_EQ(score.regions, 3);
  EXPECT_EQ(score.regions_on_change, 2);
  EXPECT_EQ(score.changes, 3);
  EXPECT_EQ(score.changes_found, 2);  // crate 3's old place in the prior frame has no region
  EXPECT_NEAR(score.Precision(), 2.0 / 3.0, 1e-12);
  // The registration shifts the other key frame 60 px to the right: crate 2 (centre u ~ 50) falls outside it.
  std::vector<cv::Rect2d> kept = prior;
  Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
  shift(0, 2) = -60.0;
  KeepInOverlap(shift, 160, 100, &kept);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_GT(kept[0].x, prior[0].x);
}

// A flight's views of a 1 m crate 10 m ahead: from 10 m and 5 m it shows whole, from 1 m it fills more than the
// frame, and from beyond it the camera looks away. Only the whole views give depths.
TEST(ChangeScore, SightingsCountTheViewsThatShowAnObjectWholeAndTheirDepths) {
  CameraPoseSample pose;  // looking along +x, as above
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0), r.col(1) = Eigen::Vector3d(0, 0, -1), r.col(2) = Eigen::Vector3d(1, 0, 0);
  pose.rotation = Eigen::Quaterniond(r);
  const CameraIntrinsics camera{100, 100, 80, 50, 160, 100};
  std::vector<CameraPoseSample> views;
  for (const double x : {0.0, 5.0, 9.0, 12.0}) {
    pose.position = Eigen::Vector3d(x, 0, 0.5);
    views.push_back(pose);
  }
  const Sightings seen = SightingsOf(Truth(1, "crate", 10, 0, 4), views, camera);
  EXPECT_EQ(seen.views, 3);  // the camera at x = 12 has it behind
  EXPECT_EQ(seen.whole, 2);  // from x = 9 its near face spans 200 px of the 160
  EXPECT_NEAR(seen.nearest_m, 5.0, 1e-9);
  EXPECT_NEAR(seen.farthest_m, 10.0, 1e-9);
  // Beside the path, 8.5 m to the left, it is cut by the frame's left edge from every view.
  const Sightings beside = SightingsOf(Truth(2, "crate", 10, 8.5, 4), {views[0]}, camera);
  EXPECT_EQ(beside.views, 1);
  EXPECT_EQ(beside.whole, 0);
  EXPECT_EQ(beside.nearest_m, 0.0);
}

// Object changes visible in two compared pairs of route frames; one reported change, and candidates that were
// dropped at different steps. Each change not found is counted once, at the furthest step any candidate on it
// reached in any pair.
TEST(ChangeScore, RouteChangesNotFoundAreCountedAtTheirFurthestStep) {
  const cv::Rect2d a(10, 10, 20, 20), b(60, 10, 20, 20), c(110, 10, 20, 20), d(10, 60, 20, 20), off(200, 200, 5, 5);
  // Pair 0: prior shows 1 (removed) and 2; current shows 3 (new). Pair 1: prior shows 2 again, current shows 4.
  const std::vector<RoutePairTruth> truth = {{{{1, a}, {2, b}}, {{3, c}}}, {{{2, b}}, {{4, d}}}};
  ReportedRouteChange reported;  // on 1, in pair 0
  reported.pairs = {0};
  reported.boxes = {{a, off}};
  const std::vector<RouteCandidate> candidates = {
      {0, {b, off}, 1, "early"},  // on 2 in pair 0 ...
      {1, {b, off}, 3, "late"},   // ... and further in pair 1
      {0, {a, off}, 0, "first"},  // on 1, which is found anyway
      {1, {off, c}, 3, "late"},   // on nothing: 3 is visible in pair 0, not 1
      {7, {off, d}, 3, "late"},   // a pair that was not scored
  };
  ReportedRouteChange astray;  // on nothing
  astray.pairs = {1};
  astray.boxes = {{off, off}};
  astray.confidence = 0.5;
  const RouteScore score = ScoreRoute(truth, {reported, astray}, candidates, ChangeScoreOptions{});
  EXPECT_EQ(score.visible, 4);
  EXPECT_EQ(score.found, 1);
  EXPECT_EQ(score.visible_in_prior, 2);  // 1 and 2, each once though 2 shows in both pairs
  EXPECT_EQ(score.found_in_prior, 1);
  EXPECT_EQ(score.changes_on_truth, 1);
  const std::map<std::string, int> expected = {{"late", 1}, {"no_region", 2}};  // 2 late; 3 and 4 none
  EXPECT_EQ(score.lost_at, expected);
  const std::vector<std::pair<double, bool>> ranked = {{0.0, true}, {0.5, false}};
  EXPECT_EQ(score.ranked, ranked);
}

// The precision at each true change's rank, averaged; a tie ranks the false change first.
TEST(ChangeScore, AveragePrecisionRewardsConfidencesThatPutTrueChangesFirst) {
  EXPECT_DOUBLE_EQ(AveragePrecision({{0.9, true}, {0.8, true}, {0.1, false}}), 1.0);
  EXPECT_DOUBLE_EQ(AveragePrecision({{0.7, true}, {0.8, false}, {0.9, true}}), (1.0 + 2.0 / 3.0) / 2.0);
  EXPECT_DOUBLE_EQ(AveragePrecision({{0.5, true}, {0.5, false}}), 0.5);
  EXPECT_DOUBLE_EQ(AveragePrecision({{0.5, false}}), 0.0);
  EXPECT_DOUBLE_EQ(AveragePrecision({}), 0.0);
}

// Crate 2 moved, 3 was removed, 5 is new, 1 stayed. An entry at the moved crate's prior place finds it, one beside
// the new crate (within 1 m of its box) finds that; one where crate 1 stands is false, a bearing is counted apart,
// and the removed barrel, which no patrol saw whole, is missed but not observable.
TEST(ChangeScore, TheChangeListIsScoredPerEntryOverAllAndObservableChanges) {
  const std::vector<TruthObject> before = {Truth(1, "crate", 0, 0, 10), Truth(2, "crate", 5, 0, 10),
                                           Truth(3, "barrel", 11, 0, 10)};
  const std::vector<TruthObject> after = {Truth(1, "crate", 0, 0, 10), Truth(2, "crate", 8, 0, 10),
                                          Truth(5, "crate", 14, 0, 10)};
  std::vector<TrueChange> truth = TrueChanges(before, after);
  ASSERT_EQ(truth.size(), 3u);
  EXPECT_EQ(truth[0].state, "moved");
  EXPECT_EQ(truth[1].state, "removed");
  EXPECT_EQ(truth[2].state, "new");
  truth[0].observable = truth[2].observable = true;
  const std::vector<ReportedEntry> entries = {{"object-p2-c2", Eigen::Vector3d(8, 0, 0.5), Eigen::Vector3d(5, 0, 0.5)},
                                              {"geometry-7_0_0", Eigen::Vector3d(15.3, 0, 0.5), std::nullopt},
                                              {"appearance-f1-1", Eigen::Vector3d(0, 0.2, 0.5), std::nullopt},
                                              {"appearance-f2-2", std::nullopt, std::nullopt}};
  const EntryScore score = ScoreEntries(entries, truth, ChangeScoreOptions());
  EXPECT_EQ(score.entries, 4);
  EXPECT_EQ(score.bearings, 1);
  EXPECT_EQ(score.true_entries, 2);
  EXPECT_EQ(score.false_ids, std::vector<std::string>{"appearance-f1-1"});
  EXPECT_EQ(score.missed_ids, std::vector<int>{3});
  EXPECT_DOUBLE_EQ(score.Precision(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(score.Recall(false), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(score.Recall(true), 1.0);
  EXPECT_DOUBLE_EQ(score.F1(true), 0.8);
}

}  // namespace
}  // namespace patrolmap::eval

namespace patrolmap::eval {
namespace {

// Object 1 kept its site id over three patrols, object 2 took a new one at the third; site id 9 was given to two
// true objects. A map object is its label's true object whose box holds it.
TEST(SiteIds, KeptChangedAndMergedIdsAcrossPatrols) {
  const SiteIdScore score = ScoreSiteIds({{{5, 1}, {6, 2}, {9, 3}}, {{5, 1}, {6, 2}, {9, 4}}, {{5, 1}, {7, 2}}});
  EXPECT_EQ(score.tracked, 4);  // 1 and 2 from the first to the second, and from the second to the third
  EXPECT_EQ(score.kept, 3);
  EXPECT_EQ(score.changed, 1);
  EXPECT_EQ(score.merged, 1);
  EXPECT_DOUBLE_EQ(score.Persistence(), 0.75);
  TruthObject crate;
  crate.id = 4;
  crate.label = "crate";
  crate.centre = Eigen::Vector2d(10.0, 0.0);
  crate.length = crate.width = crate.height = 1.0;
  MapObject seen;
  seen.label = "crate";
  seen.centroid = Eigen::Vector3d(10.3, 0.2, 0.5);
  EXPECT_EQ(TruthIdOf(seen, {crate}, ChangeScoreOptions()), 4);
  seen.label = "barrel";
  EXPECT_EQ(TruthIdOf(seen, {crate}, ChangeScoreOptions()), -1);
}

}  // namespace
}  // namespace patrolmap::eval
