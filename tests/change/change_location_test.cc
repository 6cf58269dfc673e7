#include "patrolmap/change/change_location.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "change/fixtures.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::kCamera;
using testing_fixtures::LookingAlongX;

// The centre of the 64x48 image looks along the optical axis; a box right of it looks right of it (world -y), and
// the same box on an image twice as wide is the same ray.
TEST(ChangeLocation, ABearingRunsThroughTheBoxCentre) {
  const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(1, 2, 3));
  const Bearing ahead = BearingThrough(kCamera, {}, 64, pose, cv::Rect(30, 22, 3, 3));  // centre (31.5, 23.5)
  EXPECT_TRUE(ahead.origin.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_NEAR(ahead.direction.x(), 1.0, 1e-12);
  const Bearing right = BearingThrough(kCamera, {}, 64, pose, cv::Rect(70, 22, 3, 3));  // 40 px right: 45 degrees
  EXPECT_NEAR(right.direction.x(), std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(right.direction.y(), -std::sqrt(0.5), 1e-9);
  const Bearing doubled = BearingThrough(kCamera, {}, 128, pose, cv::Rect(140, 44, 6, 6));
  EXPECT_TRUE(doubled.direction.isApprox(right.direction, 1e-9));
}

// A region's point is the median depth along the ray through its centre; too little known depth gives none, as
// does depth beyond max_range_m.
TEST(ChangeLocation, TheMedianDepthOfARegionPlacesIt) {
  KeyFrameView view;
  view.lens = depth::Lens(kCamera);
  view.pose = LookingAlongX(Eigen::Vector3d::Zero());
  view.depth = cv::Mat(kCamera.height, kCamera.width, CV_32FC1, cv::Scalar(0.0f));
  const cv::Rect box(27, 19, 10, 10);  // centre pixel (32, 24)
  view.depth(box).setTo(8.0f);
  view.depth(cv::Rect(27, 19, 10, 2)).setTo(30.0f);  // a fifth farther: the median stays
  ChangeLocationOptions options;
  const std::optional<Eigen::Vector3d> point = PointFromDepth(view, box, options);
  ASSERT_TRUE(point);
  EXPECT_NEAR(point->x(), 8.0, 1e-9);
  EXPECT_NEAR(point->y(), -0.5 * 8.0 / 40.0, 1e-9);  // pixel 32 is half a pixel right of cx
  view.depth(cv::Rect(27, 21, 10, 8)).setTo(0.0f);   // only a fifth known
  EXPECT_FALSE(PointFromDepth(view, box, options));
  view.depth(box).setTo(80.0f);
  EXPECT_FALSE(PointFromDepth(view, box, options));  // beyond 60 m
}

// Along a bearing the first occupied voxel is the surface; free voxels before it and none at all give nothing more.
TEST(ChangeLocation, TheFirstOccupiedVoxelOnTheBearingIsTheSurface) {
  EvidenceGridData grid;
  grid.voxel_size = 0.5;
  for (int x = 1; x <= 20; ++x) grid.voxels.push_back({x, 0, 0, 0, 5});  // free
  grid.voxels.back() = {20, 0, 0, 6, 1};                                 // the wall 10 m ahead
  grid.voxels.push_back({24, 0, 0, 6, 0});                               // behind it
  const Bearing ahead{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()};
  const std::optional<Eigen::Vector3d> surface = FirstSurface(LookupIn(grid), 0.5, ahead, ChangeLocationOptions());
  ASSERT_TRUE(surface);
  EXPECT_NEAR(surface->x(), 10.0, 1e-9);
  const Bearing aside{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()};
  EXPECT_FALSE(FirstSurface(LookupIn(grid), 0.5, aside, ChangeLocationOptions()));
  ChangeLocationOptions near;
  near.max_range_m = 8.0;
  EXPECT_FALSE(FirstSurface(LookupIn(grid), 0.5, ahead, near));
}

// Rays from two cameras 2 m apart meet at the point they look at; rays almost parallel, or meeting behind a camera,
// place nothing.
TEST(ChangeLocation, RaysFarEnoughApartAreTriangulated) {
  const Eigen::Vector3d target(10.0, 1.0, 2.0);
  const auto ray = [&](const Eigen::Vector3d& origin) { return Bearing{origin, (target - origin).normalized()}; };
  const ChangeLocationOptions options;
  const std::optional<Eigen::Vector3d> met = Triangulate({ray({0, 0, 2}), ray({0, 2, 2}), ray({0, 1, 2.5})}, options);
  ASSERT_TRUE(met);
  EXPECT_TRUE(met->isApprox(target, 1e-9));
  EXPECT_FALSE(Triangulate({ray({0, 0, 2})}, options));
  EXPECT_FALSE(Triangulate({ray({0, 0, 2}), ray({0, 0.1, 2})}, options));  // 0.6 degrees apart
  const Eigen::Vector3d away = ray({0, 2, 2}).direction;  // on the same line, beyond the target, looking on
  EXPECT_FALSE(Triangulate({ray({0, 0, 2}), Bearing{target + 5.0 * away, away}}, options));
}

}  // namespace
}  // namespace patrolmap::change
