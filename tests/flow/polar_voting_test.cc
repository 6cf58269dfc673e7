#include <cmath>
#include <numeric>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "patrolmap/flow/edge_flow.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/flow/polar_voting.h"
#include "patrolmap/flow/signal.h"

namespace patrolmap::flow {
namespace {

TEST(Polar, FollowsEquationsOneAndTwo) {
  const PolarVector a = ToPolar({{10.0f, 20.0f}, {3.0f, 4.0f}});
  EXPECT_NEAR(a.theta, std::atan2(4.0, 3.0), 1e-6);
  EXPECT_NEAR(a.r, 10.0 * 0.6 + 20.0 * 0.8, 1e-4);
  EXPECT_NEAR(a.length, 5.0, 1e-6);
  const PolarVector left = ToPolar({{50.0f, 7.0f}, {-2.0f, 0.0f}});
  EXPECT_NEAR(std::abs(left.theta), M_PI, 1e-6);
  EXPECT_NEAR(left.r, -50.0, 1e-4);
  EXPECT_NEAR(left.length, 2.0, 1e-6);
}

// Runs the voter over frames that each hold the given vectors; returns per frame whether vector 0 passed.
std::vector<int> VoteSequence(HysteresisVoter* voter, const std::vector<std::vector<PolarVector>>& frames) {
  std::vector<int> passed;
  std::vector<std::uint8_t> accepted;
  for (const auto& vectors : frames) {
    voter->Vote(vectors, &accepted);
    passed.push_back(vectors.empty() ? -1 : accepted[0]);
  }
  return passed;
}

// Table I's hysteresis, cell by cell (paper 002 §III-A): a cell is accepted once its vote reaches 3 and
// dropped when it falls under 2; a vector passes when the frames before it have accepted its cell.
TEST(HysteresisVoter, AcceptsAfterThreeVotesAndDropsUnderTwo) {
  const VotingOptions options;  // accept 3, reject 2 (Table I)
  const PolarVector v = ToPolar({{100.0f, 50.0f}, {-8.0f, 0.0f}});
  HysteresisVoter voter(options, 376, 240);
  // Votes after each frame: 1, 2, 3 (accepted), 4th frame passes; absent twice: 2 (kept), 1 (dropped);
  // present: not accepted before, vote 2; present: vote 3, accepted again; present: passes.
  EXPECT_EQ(VoteSequence(&voter, {{v}, {v}, {v}, {v}, {}, {}, {v}, {v}, {v}}),
            (std::vector<int>{0, 0, 0, 1, -1, -1, 0, 0, 1}));
  voter.Reset();
  // The hysteresis itself: absent once, the vote falls to 2 -- under accept, not under reject -- and the
  // cell's vectors pass again at once. Without it (dropping under accept) the 5th frame would not pass.
  EXPECT_EQ(VoteSequence(&voter, {{v}, {v}, {v}, {}, {v}}), (std::vector<int>{0, 0, 0, -1, 1}));
  // With reject = accept there is no band: the same sequence drops the cell on the miss.
  VotingOptions no_band = options;
  no_band.reject = 3;
  HysteresisVoter plain(no_band, 376, 240);
  EXPECT_EQ(VoteSequence(&plain, {{v}, {v}, {v}, {}, {v}}), (std::vector<int>{0, 0, 0, -1, 0}));
}

TEST(HysteresisVoter, RandomDirectionsAreNeverAccepted) {
  HysteresisVoter voter(VotingOptions{}, 376, 240);
  cv::RNG rng(7);
  std::vector<std::uint8_t> accepted;
  int total = 0;
  for (int frame = 0; frame < 50; ++frame) {
    std::vector<PolarVector> vectors;
    for (int i = 0; i < 5; ++i) {
      vectors.push_back(ToPolar(
          {{rng.uniform(0.f, 376.f), rng.uniform(0.f, 240.f)}, {rng.uniform(-5.f, 5.f), rng.uniform(-5.f, 5.f)}}));
    }
    total += voter.Vote(vectors, &accepted);
  }
  EXPECT_LE(total, 3);  // 250 scattered vectors over ~2,700 cells: chance repeats only
}

TEST(SceneFlowResponse, AveragesAcceptedQuantityInImageWidths) {
  std::vector<PolarVector> vectors(3);
  vectors[0].length = 10, vectors[1].length = 20, vectors[2].length = 30;
  vectors[0].r = 5, vectors[1].r = -7, vectors[2].r = 9;
  const std::vector<std::uint8_t> accepted = {1, 0, 1};
  EXPECT_DOUBLE_EQ(SceneFlowResponse(vectors, accepted, ResponseQuantity::kLength, 100), 0.2);
  EXPECT_DOUBLE_EQ(SceneFlowResponse(vectors, accepted, ResponseQuantity::kLineParameter, 100), 0.07);
  EXPECT_TRUE(std::isnan(SceneFlowResponse(vectors, {0, 0, 0}, ResponseQuantity::kLength, 100)));
}

}  // namespace
}  // namespace patrolmap::flow
