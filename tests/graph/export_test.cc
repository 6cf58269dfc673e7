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
using testing_fixtures::CountOf;

// A flight id written to close the page's script and run its own: every text format escapes it.
TEST(Export, HostileFlightIdsAreEscapedInEveryTextFormat) {
  TopoMap map = TwoFlights();
  const std::string hostile = "x</script><img src=x onerror=alert(1)>&\xff";
  for (int i = 0; i < map.node_count(); ++i) map.mutable_node(i).flight = hostile;
  const std::string html = ToHtml(map);
  EXPECT_EQ(html.find("<img src=x"), std::string::npos);
  EXPECT_EQ(CountOf(html, "</script>"), 2u);  // the JSON element's and the script's own, no third
  EXPECT_NE(html.find("x\\u003c/script\\u003e"), std::string::npos);
  for (const std::string& text : {ToGraphML(map), ToSvg(map), ToKml(map)}) {
    EXPECT_EQ(text.find("<img"), std::string::npos);
    EXPECT_NE(text.find("x&lt;/script&gt;&lt;img"), std::string::npos);
  }
  const nlohmann::json json = nlohmann::json::parse(ToJson(map));  // invalid UTF-8 replaced, not thrown
  EXPECT_EQ(json["nodes"].size(), 7u);
  map.mutable_node(0).flight = "a\"b";
  EXPECT_NE(ToDot(map).find("flight=\"a\\\"b\""), std::string::npos);  // DOT strings escape their quotes
}

TEST(Export, GraphMLKeepsFullPrecisionAndJsonIsNodeLink) {
  const TopoMap map = TwoFlights();
  const std::string graphml = ToGraphML(map);
  const std::string tag = "<data key=\"lat\">";
  const std::size_t at = graphml.find(tag);
  ASSERT_NE(at, std::string::npos);
  const std::string latitude = graphml.substr(at + tag.size(), graphml.find('<', at + tag.size()) - at - tag.size());
  EXPECT_EQ(std::stod(latitude), 47.3572123456789);  // exactly the stored double, not 47.3572
  const nlohmann::json json = nlohmann::json::parse(ToJson(map));
  EXPECT_EQ(json["graph"]["schema"], "patrolmap.map/1");
  EXPECT_EQ(json["nodes"].size(), 7u);
  EXPECT_EQ(json["links"].size(), 8u);
  EXPECT_EQ(json["links"][5]["kind"], "loop_closure");
  EXPECT_EQ(json["links"][5]["inliers"], 88);
  EXPECT_DOUBLE_EQ(json["nodes"][2]["gps"][0].get<double>(), 47.3572123456789);
  EXPECT_TRUE(json["nodes"][0]["gps"].is_null());
  EXPECT_EQ(CountOf(ToDot(map), "style=dashed"), 3u);
}

TEST(Export, SvgColoursLoopClosuresByTruth) {
  const TopoMap map = TwoFlights();
  const std::string plain = ToSvg(map);
  EXPECT_EQ(plain.find("#dc2626"), std::string::npos);
  SvgTruth truth;
  truth.loop_closure_correct = {true, false, true};  // 4~1 correct, 6~3 false, 5~1 correct
  truth.missed = {{6, 2}};
  const std::string judged = ToSvg(map, &truth);
  EXPECT_EQ(CountOf(judged, "stroke='#16a34a'"), 2u);  // correct closures
  EXPECT_EQ(CountOf(judged, "stroke='#dc2626'"), 1u);  // the false one
  EXPECT_EQ(CountOf(judged, "stroke='#2563eb'"), 1u);  // the missed pair
  EXPECT_NE(judged.find("missed loop closure"), std::string::npos);
}

// Two nodes of one place laid out at one spot: their loop closure is a ring around them, not a line of no
// length; the others are curves. Each is a clickable group naming its index.
TEST(Export, ClosuresBetweenCoincidentNodesAreRings) {
  TopoMap map = TwoFlights();
  map.mutable_node(4).layout = map.node(1).layout;  // closure 4~1
  const std::string svg = ToSvg(map);
  EXPECT_EQ(CountOf(svg, "class='closure'"), 3u);
  EXPECT_NE(svg.find("<g class='closure' data-edge='0'><circle"), std::string::npos);
  EXPECT_NE(svg.find("<g class='closure' data-edge='1'><path d='M"), std::string::npos);
  // The page keeps the legend out of the drawing and carries each closure's matches.
  std::vector<ClosureMatches> matches(3);
  matches[1].pairs = {{1.5f, 2.0f, 3.0f, 4.0f}};
  const std::string html = ToHtml(map, nullptr, &matches);
  EXPECT_EQ(html.find("<text x='10' y='18'"), std::string::npos);
  EXPECT_NE(html.find("<div class='legend'>"), std::string::npos);
  EXPECT_NE(html.find("\"matches\":[[1.5,2.0,3.0,4.0]]"), std::string::npos);
  EXPECT_NE(html.find("7 nodes, 3 loop closures, 2 flights."), std::string::npos);
}

}  // namespace
}  // namespace patrolmap::graph
