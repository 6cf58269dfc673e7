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

TEST(Layout, OdometryJacobianMatchesNumericDifferentiation) {
  const double a[3] = {1.2, -0.7, 0.9}, b[3] = {3.1, 0.4, 1.7};
  const Eigen::Vector2d step(1.5, 0.3);
  double residual[3], ja[9], jb[9];
  OdometryResidual(a, b, step, 0.6, 7.0, residual, ja, jb);
  const double h = 1e-6;
  for (int p = 0; p < 3; ++p) {
    for (int which = 0; which < 2; ++which) {
      double plus[3], minus[3], rp[3], rm[3];
      std::copy(which == 0 ? a : b, (which == 0 ? a : b) + 3, plus);
      std::copy(which == 0 ? a : b, (which == 0 ? a : b) + 3, minus);
      plus[p] += h, minus[p] -= h;
      OdometryResidual(which == 0 ? plus : a, which == 0 ? b : plus, step, 0.6, 7.0, rp, nullptr, nullptr);
      OdometryResidual(which == 0 ? minus : a, which == 0 ? b : minus, step, 0.6, 7.0, rm, nullptr, nullptr);
      for (int r = 0; r < 3; ++r) {
        const double numeric = (rp[r] - rm[r]) / (2 * h);
        EXPECT_NEAR((which == 0 ? ja : jb)[r * 3 + p], numeric, 1e-6) << "residual " << r << " parameter " << p;
      }
    }
  }
}

// A square loop of 4 x 10 nodes one second apart; the integrated headings drift by 0.01 rad a node.
TopoMap SquareLoop(LayoutInput* input) {
  TopoMap map;
  input->heading.clear();
  for (int i = 0; i <= 40; ++i) {
    KeyFrameNode node;
    node.flight = "a";
    node.timestamp_ns = SecondsToNs(i);
    map.AddNode(node);
    if (i > 0) map.AddEdge(i - 1, i, EdgeData{});
    input->heading.push_back((i / 10) * M_PI / 2 + 0.01 * i);
  }
  return map;
}

// The odometry residual by hand: a at (1, 2) facing +y, b 3 units ahead of it and turned by 0.2 rad. Seen
// from a, b lies at (3, 0); against a step of (3, 0.5) and a turn of 0.1 the residual is (0, -0.5, w 0.1).
TEST(Layout, OdometryResidualIsTheStepSeenFromTheFirstPoseLessTheMeasuredStep) {
  const double a[3] = {1.0, 2.0, M_PI / 2}, b[3] = {1.0, 5.0, M_PI / 2 + 0.2};
  double residual[3];
  OdometryResidual(a, b, Eigen::Vector2d(3.0, 0.5), 0.1, 10.0, residual, nullptr, nullptr);
  EXPECT_NEAR(residual[0], 0.0, 1e-12);
  EXPECT_NEAR(residual[1], -0.5, 1e-12);
  EXPECT_NEAR(residual[2], 10.0 * 0.1, 1e-12);
  const double left[3] = {0.0, 2.0, M_PI / 2};  // one unit to a's left (a faces +y, so left is -x)
  OdometryResidual(a, left, Eigen::Vector2d(0.0, 0.0), 0.0, 1.0, residual, nullptr, nullptr);
  EXPECT_NEAR(residual[0], 0.0, 1e-12);
  EXPECT_NEAR(residual[1], 1.0, 1e-12);
  EXPECT_NEAR(residual[2], 0.0, 1e-12);
  // Headings wrap: from 179 to -179 degrees is a turn of +2 degrees, not -358.
  const double before[3] = {0.0, 0.0, M_PI - 0.0174533}, after[3] = {0.0, 0.0, -M_PI + 0.0174533};
  OdometryResidual(before, after, Eigen::Vector2d(0.0, 0.0), 0.0349066, 1.0, residual, nullptr, nullptr);
  EXPECT_NEAR(residual[2], 0.0, 1e-6);
}

TEST(Layout, LoopClosureClosesTheSquareAndAFalseOneDoesNotFoldIt) {
  LayoutInput input;
  TopoMap open = SquareLoop(&input);
  ASSERT_TRUE(LayoutMap(input, {}, &open).ok());
  const double gap = (open.node(40).layout - open.node(0).layout).norm();
  EXPECT_GT(gap, 2.0);  // the heading drift leaves the loop open
  TopoMap closed = SquareLoop(&input);
  closed.AddEdge(40, 0, {EdgeKind::kLoopClosure, 0.5, 0.5, 100});
  closed.AddEdge(25, 5, {EdgeKind::kLoopClosure, 0.1, 0.2, 50});  // false: opposite sides, 10 m apart
  ASSERT_TRUE(LayoutMap(input, {}, &closed).ok());
  EXPECT_LT((closed.node(40).layout - closed.node(0).layout).norm(), 0.3 * gap);
  EXPECT_GT((closed.node(25).layout - closed.node(5).layout).norm(), 6.0);          // the robust loss keeps them apart
  EXPECT_NEAR((closed.node(10).layout - closed.node(0).layout).norm(), 10.0, 1.5);  // sides keep their length
}

TEST(Layout, AFirstNodeWithoutEdgesIsLaidOutToo) {
  // A one-node flight (a log stopped after its first key location) followed by a two-node one.
  TopoMap map;
  LayoutInput input;
  for (const char* flight : {"a", "b", "b"}) {
    KeyFrameNode node;
    node.flight = flight;
    node.timestamp_ns = 1'000'000'000LL * map.node_count();
    map.AddNode(std::move(node));
    input.heading.push_back(0.0);
  }
  TopoMap single;
  single.AddNode(KeyFrameNode{});
  LayoutInput one;
  one.heading = {0.0};
  ASSERT_TRUE(LayoutMap(one, {}, &single).ok());
  EXPECT_EQ(single.node(0).layout, Eigen::Vector2d::Zero());
  map.AddEdge(1, 2, EdgeData{});
  ASSERT_TRUE(LayoutMap(input, {}, &map).ok());
  EXPECT_NEAR((map.node(2).layout - map.node(1).layout).norm(), 1.0, 1e-6);
}

}  // namespace
}  // namespace patrolmap::graph
