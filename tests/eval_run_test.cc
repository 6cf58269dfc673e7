#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/eval/run_score.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/sim/flight.h"
#include "test_util.h"

namespace patrolmap::eval {
namespace {

// A short street flown once, written as flight `id` in `folder`.
void WriteStreet(const std::string& id, const std::string& folder) {
  sim::StreetOptions street;
  street.speed_mps = 5.0;
  sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flight.flight_id = id;
  ASSERT_TRUE(sim::WriteEurocLog(flight, folder).ok());
}

// The truth of a flight: `objects` (id, label, x, y; 1 m cubes), each seen by the detector at times 1..5 ns.
void WriteObjects(const std::string& log, const std::vector<std::tuple<int, std::string, double, double>>& objects) {
  std::string table = "#id,label,x [m],y [m],yaw [rad],length [m],width [m],height [m]\n";
  std::string seen = "#timestamp [ns],detection,object_id\n";
  for (const auto& [id, label, x, y] : objects) {
    table += std::to_string(id) + "," + label + "," + std::to_string(x) + "," + std::to_string(y) + ",0,1,1,1\n";
    for (int t = 1; t <= 5; ++t) seen += std::to_string(t) + ",0," + std::to_string(id) + "\n";
  }
  testing::WriteText(log + "/groundtruth/objects.csv", table);
  testing::WriteText(log + "/groundtruth/detections.csv", seen);
}

// The key locations a detection run wrote score as the scores of its own detections do.
TEST(ScoreRun, KeyLocationsOfADetectionRunScoreAsItsDetections) {
  testing::TempDir dir;
  WriteStreet("street", dir / "log");
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(dir / "log", {}, &source).ok());
  pipeline::DetectionResult result;
  ASSERT_TRUE(pipeline::RunDetection(source.get(), flow::KeyLocationOptions{}, &result).ok());
  ASSERT_TRUE(pipeline::WriteDetectionOutputs(result, dir / "run", {}).ok());
  std::vector<TruthEdge> edges;
  ASSERT_TRUE(ReadTruthEdges(dir / "log", &edges).ok());
  const KeyLocationScore expected = ScoreKeyLocations(result.key_locations, edges, {});
  nlohmann::json score;
  ASSERT_TRUE(ScoreRun(dir / "run", {dir / "log"}, {}, &score).ok());
  const nlohmann::json& k = score["key_locations"];
  EXPECT_EQ(k["flight"], "street");
  EXPECT_EQ(k["true_positives"].get<int>(), expected.true_positives);
  EXPECT_EQ(k["false_positives"].get<int>(), expected.false_positives);
  EXPECT_EQ(k["missed"].get<int>(), expected.missed);
  EXPECT_EQ(k["spans"].size(), expected.spans.size());
  EXPECT_FALSE(score.contains("changes"));
  const std::string tables = RunScoreTables(score, true);
  EXPECT_NE(tables.find("key locations (paper 002 Table II)"), std::string::npos);
  EXPECT_NE(tables.find("  span    -inf .. "), std::string::npos) << tables;
}

// A change report without a map is scored on its objects: per state and over the true changes as a whole.
TEST(ScoreRun, ObjectsOfAChangeReportPerStateAndAsAWhole) {
  testing::TempDir dir;
  WriteStreet("a", dir / "a");
  WriteStreet("b", dir / "b");
  // Crate 1 was removed, barrel 2 came, vehicle 3 stayed; the report finds the crate, misses the barrel and
  // reports a new crate where nothing came.
  WriteObjects(dir / "a", {{1, "crate", 10.0, 2.0}, {3, "vehicle", 20.0, 2.0}});
  WriteObjects(dir / "b", {{2, "barrel", 15.0, -2.0}, {3, "vehicle", 20.0, 2.0}});
  const nlohmann::json changes = {
      {"format", "patrolmap.changes"},
      {"prior_flight", "a"},
      {"current_flight", "b"},
      {"summary", {{"places_compared", 4}, {"places_changed", 1}}},
      {"objects",
       {{{"id", "object-1"},
         {"state", "removed"},
         {"label", "crate"},
         {"before", {10.2, 2.0, 0.5}},
         {"after", nullptr}},
        {{"id", "object-2"}, {"state", "new"}, {"label", "crate"}, {"before", nullptr}, {"after", {30.0, 0.0, 0.5}}}}},
      {"changes", nlohmann::json::array()}};
  testing::WriteText(dir / "run/changes.json", changes.dump());
  nlohmann::json score;
  ASSERT_TRUE(ScoreRun(dir / "run", {dir / "a", dir / "b"}, {}, &score).ok());
  const nlohmann::json& objects = score["changes"]["objects"];
  EXPECT_EQ(objects["removed"]["true_positives"], 1);
  EXPECT_EQ(objects["new"]["false_negatives"], 1);
  EXPECT_EQ(objects["new"]["false_positives"], 1);
  EXPECT_EQ(objects["changes"]["true_positives"], 1);  // of crate 1 and barrel 2
  EXPECT_EQ(objects["changes"]["false_negatives"], 1);
  EXPECT_EQ(objects["changes"]["false_positives"], 1);
  EXPECT_FALSE(objects.contains("observable_changes"));  // observability needs the run's map
  EXPECT_EQ(score["changes"]["places_compared"], 4);
  EXPECT_NE(RunScoreTables(score, false).find("object changes"), std::string::npos);
}

TEST(ScoreRun, ARunItCannotScoreIsRefusedNamingWhy) {
  testing::TempDir dir;
  WriteStreet("a", dir / "a");
  nlohmann::json score;
  std::filesystem::create_directories(dir / "empty");
  Status status = ScoreRun(dir / "empty", {dir / "a"}, {}, &score);
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_NE(status.message().find("holds none of"), std::string::npos);
  testing::WriteText(dir / "run/changes.json",
                     R"({"format": "patrolmap.changes", "prior_flight": "a", "current_flight": "z", "summary": {}})");
  status = ScoreRun(dir / "run", {dir / "a"}, {}, &score);
  EXPECT_NE(status.message().find("pass both logs with --log"), std::string::npos) << status.message();
  testing::WriteText(dir / "run/changes.json", "{]");
  status = ScoreRun(dir / "run", {dir / "a"}, {}, &score);
  EXPECT_NE(status.message().find(dir / "run/changes.json"), std::string::npos) << status.message();
  status = ScoreRun(dir / "run", {dir / "missing"}, {}, &score);
  EXPECT_NE(status.message().find("missing"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace patrolmap::eval
