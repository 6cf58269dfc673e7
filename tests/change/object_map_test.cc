#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "change/fixtures.h"
#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/object_map.h"

namespace patrolmap::change {
namespace {

using testing_fixtures::kCamera;
using testing_fixtures::LookingAlongX;

std::vector<Eigen::Vector3f> BoxPoints(const Eigen::Vector3f& centre, float size, float spacing) {
  std::vector<Eigen::Vector3f> points;
  const int n = static_cast<int>(size / spacing);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const float a = -size / 2 + i * spacing, b = -size / 2 + j * spacing;
      for (const Eigen::Vector3f& p :
           {Eigen::Vector3f(-size / 2, a, b), Eigen::Vector3f(a, -size / 2, b), Eigen::Vector3f(a, b, size / 2)}) {
        points.push_back(centre + p);
      }
    }
  }
  return points;
}

TEST(PointPairs, FractionOfNearestNeighboursWithinTheThreshold) {
  const std::vector<Eigen::Vector3f> box = BoxPoints(Eigen::Vector3f(1, 2, 0.5), 1.0f, 0.1f);
  EXPECT_DOUBLE_EQ(PairFraction(box, box, 0.01), 1.0);
  std::vector<Eigen::Vector3f> shifted = box;
  for (Eigen::Vector3f& p : shifted) p.x() += 1.5f;
  EXPECT_DOUBLE_EQ(PairFraction(shifted, box, 0.1), 0.0);
  EXPECT_DOUBLE_EQ(PairFraction({}, box, 0.1), 0.0);
  std::vector<Eigen::Vector3f> filtered = box;
  VoxelFilter(0.25, &filtered);
  EXPECT_LT(filtered.size(), box.size() / 3);
  EXPECT_GT(filtered.size(), 20u);
}

TEST(Registration, RecoversTheRotationOfAMovedObject) {
  cv::RNG rng(4);
  std::vector<Eigen::Vector3f> before;
  for (int i = 0; i < 400; ++i) {  // an elongated, lopsided cloud (a vehicle with a cab)
    const float x = static_cast<float>(rng.uniform(-2.0, 2.0));
    const float z = static_cast<float>(rng.uniform(0.0, x > 1.0f ? 1.8 : 1.2));
    before.emplace_back(x, static_cast<float>(rng.uniform(-0.8, 0.8)), z);
  }
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3f> after;
  for (const Eigen::Vector3f& p : before)
    after.push_back((rotation * p.cast<double>()).cast<float>() + Eigen::Vector3f(5, 1, 0));
  const Eigen::Matrix3d found = RegisterRotation(before, after);
  EXPECT_LT((found - rotation).norm(), 1e-6);
  EXPECT_TRUE(RegisterRotation({}, after).isIdentity());
}

ObjectObservation Detection(const std::string& label, double confidence, const CameraPoseSample& pose,
                            const Eigen::Vector3d& world, double noise, cv::RNG* rng) {
  ObjectObservation o;
  o.label = label;
  o.confidence = confidence;
  const Eigen::Vector3d c =
      pose.ToCamera(world) + noise * Eigen::Vector3d(rng->gaussian(1), rng->gaussian(1), rng->gaussian(1));
  o.centroid_camera = c;
  const double u = kCamera.fx * c.x() / c.z() + kCamera.cx, v = kCamera.fy * c.y() / c.z() + kCamera.cy;
  const double half = kCamera.fx * 0.5 / c.z();
  o.box = cv::Rect2d(u - half, v - half, 2 * half, 2 * half);
  return o;
}

TEST(ObjectMap, DetectionsBecomeObjectsWithAccumulatedLabels) {
  ObjectMapOptions options;
  ObjectMapper mapper(options, kCamera);
  cv::RNG rng(7);
  const Eigen::Vector3d crate(10, 0.5, 0.5), barrel(12, -1.0, 0.5), ghost(9, 2.0, 0.5);
  for (int frame = 0; frame < 12; ++frame) {
    const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0.2 * frame, 0, 1.5));
    std::vector<ObjectObservation> detections = {
        Detection("crate", 0.8, pose, crate, 0.1, &rng),
        Detection(frame % 4 == 0 ? "barrel" : "crate", 0.6, pose, barrel, 0.1, &rng)};
    if (frame == 5) detections.push_back(Detection("crate", 0.9, pose, ghost, 0.1, &rng));  // one false detection
    mapper.AddFrame(detections, pose, cv::Mat(), cv::Mat());
  }
  const std::vector<MapObject> objects = mapper.Finish();
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_TRUE(objects[0].confirmed && objects[1].confirmed);
  EXPECT_FALSE(objects[2].confirmed);  // the single false detection is below min_detections
  EXPECT_EQ(objects[2].detections, 1);
  EXPECT_EQ(objects[0].label, "crate");
  EXPECT_NEAR(objects[0].confidence, 0.8, 1e-9);
  EXPECT_EQ(objects[0].detections, 12);
  EXPECT_LT((objects[0].centroid - crate).norm(), 0.1);
  // The second object was called a barrel 3 times and a crate 9 times: crate wins, its mean confidence stays.
  EXPECT_EQ(objects[1].label, "crate");
  EXPECT_NEAR(objects[1].confidence, 0.6, 1e-9);
  ASSERT_EQ(objects[1].labels.size(), 2u);
  EXPECT_EQ(mapper.associations(), 25);
}

// At change.object_map.max_objects the map forgets an unconfirmed object before any confirmed one, the one
// seen longest ago first.
TEST(ObjectMap, AFullMapForgetsTheUnconfirmedObjectSeenLongestAgo) {
  ObjectMapOptions options;
  options.max_objects = 3;
  ObjectMapper mapper(options, kCamera);
  cv::RNG rng(7);
  const Eigen::Vector3d crate(10, 0.5, 0.5), barrel(12, -1.0, 0.5), ghost(9, 2.0, 0.5), ghost2(11, 2.5, 0.5);
  for (int frame = 0; frame < 8; ++frame) {
    const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0.2 * frame, 0, 1.5));
    std::vector<ObjectObservation> detections = {Detection("crate", 0.8, pose, crate, 0.1, &rng)};
    if (frame < 6) detections.push_back(Detection("barrel", 0.6, pose, barrel, 0.1, &rng));  // seen longest ago
    if (frame == 4) detections.push_back(Detection("crate", 0.9, pose, ghost, 0.1, &rng));
    if (frame == 7) detections.push_back(Detection("crate", 0.9, pose, ghost2, 0.1, &rng));
    for (ObjectObservation& detection : detections) detection.timestamp_ns = frame;
    mapper.AddFrame(detections, pose, cv::Mat(), cv::Mat());
  }
  EXPECT_EQ(mapper.forgotten(), 1);
  const std::vector<MapObject> objects = mapper.Finish();
  ASSERT_EQ(objects.size(), 3u);  // crate, barrel and the second ghost: the first ghost went, not the barrel
  EXPECT_LT((objects[1].centroid - barrel).norm(), 0.2);
  EXPECT_LT((objects[2].centroid - ghost2).norm(), 0.2);
}

TEST(ObjectMap, PointPairTestSeparatesNeighboursTheGateCannot) {
  ObjectMapOptions options;
  options.centroid_gate_m = 1.5;
  ObjectMapper mapper(options, kCamera);
  cv::RNG rng(2);
  // Two crates 0.9 m apart, inside each other's centroid gate, each seen with its depth.
  const Eigen::Vector3d a(8, 0.45, 0.5), b(8, -0.45, 0.5);
  const CameraPoseSample pose = LookingAlongX(Eigen::Vector3d(0, 0, 0.5));
  for (int frame = 0; frame < 6; ++frame) {
    cv::Mat depth(kCamera.height, kCamera.width, CV_32FC1, cv::Scalar(0));
    std::vector<ObjectObservation> detections;
    for (const Eigen::Vector3d& centre : {a, b}) {
      ObjectObservation o = Detection("crate", 0.7, pose, centre, 0.0, &rng);
      const cv::Rect box = cv::Rect(o.box) & cv::Rect(0, 0, kCamera.width, kCamera.height);
      depth(box).setTo(centre.x() - 0.4);  // their front faces
      detections.push_back(o);
    }
    mapper.AddFrame(detections, pose, depth, cv::Mat());
  }
  const std::vector<MapObject> objects = mapper.Finish();
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_FALSE(objects[0].points.empty());
  EXPECT_EQ(objects[0].detections + objects[1].detections, 12);
}

}  // namespace
}  // namespace patrolmap::change
