// Appearance along the route (route_compare.h): route frames aligned and compared, regions voted over
// consecutive pairs; and real same-scene pairs (Debian's opencv-doc) that must give no region.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/route_compare.h"

namespace patrolmap::change {
namespace {

constexpr int kFrameWidth = 376, kFrameHeight = 240, kStepPx = 40, kFrames = 14;

// A long textured facade: the camera flies along it.
cv::Mat Facade(int seed) {
  cv::Mat facade(kFrameHeight, kFrameWidth + kStepPx * (kFrames + 2), CV_8UC1, cv::Scalar(110));
  cv::RNG rng(seed);
  for (int i = 0; i < 700; ++i) {
    const cv::Point a(rng.uniform(0, facade.cols), rng.uniform(0, facade.rows));
    cv::rectangle(facade, a, a + cv::Point(rng.uniform(4, 30), rng.uniform(4, 30)), cv::Scalar(rng.uniform(0, 255)),
                  cv::FILLED);
  }
  cv::GaussianBlur(facade, facade, cv::Size(3, 3), 0.7);
  return facade;
}

// Frames every kStepPx along the facade (first at `offset_px`), one a second, as JPEG route frames.
std::vector<RouteFrame> Route(const cv::Mat& facade, int offset_px, double gain, double bias) {
  std::vector<RouteFrame> route;
  for (int i = 0; i < kFrames; ++i) {
    cv::Mat frame;
    facade(cv::Rect(offset_px + i * kStepPx, 0, kFrameWidth, kFrameHeight)).convertTo(frame, CV_8U, gain, bias);
    RouteFrame f;
    f.timestamp_ns = SecondsToNs(1.0 + i);
    f.frame_index = 30 * i;
    cv::imencode(".jpg", frame, f.jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
    route.push_back(std::move(f));
  }
  return route;
}

// A grey image as a route frame: scaled to the route frames' width and JPEG-encoded at `jpeg_quality` (95 is
// OpenCV's default).
RouteFrame AsRouteFrame(const cv::Mat& grey, int jpeg_quality) {
  cv::Mat scaled;
  cv::resize(grey, scaled, cv::Size(), static_cast<double>(kFrameWidth) / grey.cols,
             static_cast<double>(kFrameWidth) / grey.cols, cv::INTER_AREA);
  RouteFrame frame;
  cv::imencode(".jpg", scaled, frame.jpeg, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
  return frame;
}

// ... and as the comparison sees it.
KeyFrameView RouteView(const cv::Mat& grey, int jpeg_quality) {
  return RouteFrameView(AsRouteFrame(grey, jpeg_quality), RouteCompareOptions{}.max_features);
}

// Whether some view of the change outlines the object at facade columns [x0, x1) in its current frame.
bool OnObject(const RouteComparison& comparison, const RouteChange& change, int offset_px, int x0, int x1,
              const cv::Rect& rows) {
  for (const RouteChange::View& v : change.views) {
    const RoutePair& pair = comparison.pairs[v.pair];
    const cv::Rect object(x0 - offset_px - pair.current * kStepPx, rows.y, x1 - x0, rows.height);
    const cv::Rect& box = pair.appearance.regions[v.region].current_box;
    if ((box & object).area() < 0.5 * std::min(box.area(), object.area())) return false;
  }
  return true;
}

TEST(RouteCompare, EveryFrameIsAlignedAndALightingChangeGivesNoChange) {
  const cv::Mat facade = Facade(3);
  const std::vector<RouteFrame> prior = Route(facade, 0, 1.0, 0.0);
  const std::vector<RouteFrame> current = Route(facade, 12, 0.7, 25.0);  // 12 px on, darker
  const RouteComparison comparison =
      CompareRoutes(prior, current, {{SecondsToNs(3.0), SecondsToNs(3.0)}}, RouteCompareOptions{}, AppearanceOptions{});
  ASSERT_TRUE(comparison.compared);
  EXPECT_EQ(comparison.current_frames, kFrames);
  EXPECT_EQ(static_cast<int>(comparison.pairs.size()), kFrames);
  for (const RoutePair& pair : comparison.pairs) EXPECT_EQ(pair.prior, pair.current);  // 12 px beats 28 px
  EXPECT_TRUE(comparison.changes.empty());
}

// The camera flying along the facade as Route shows it: kStepPx of image motion a second is a wall
// kWallDistanceM away at kStepM a second (f = 230 px).
constexpr double kStepM = 1.0, kFocalPx = 230.0, kWallDistanceM = kFocalPx * kStepM / kStepPx;

// Route's frames with the poses that fly them (world axes = the camera's), the first at `offset_px`.
std::vector<RouteFrame> WithPoses(std::vector<RouteFrame> route, int offset_px) {
  for (std::size_t i = 0; i < route.size(); ++i) {
    CameraPoseSample pose;
    pose.timestamp_ns = route[i].timestamp_ns;
    pose.position.x() = (offset_px + static_cast<double>(i) * kStepPx) * kWallDistanceM / kFocalPx;
    route[i].pose = pose;
  }
  return route;
}

TEST(RouteCompare, FramesWithPosesGetDepthAndAWallSeenAgainStaysUnchanged) {
  const cv::Mat facade = Facade(3);
  const std::vector<RouteFrame> prior = WithPoses(Route(facade, 0, 1.0, 0.0), 0);
  const std::vector<RouteFrame> current = WithPoses(Route(facade, 12, 0.7, 25.0), 12);
  const CameraIntrinsics camera{kFocalPx, kFocalPx, 187.5, 119.5, kFrameWidth, kFrameHeight};
  const RouteComparison comparison =
      CompareRoutes(prior, current, {}, RouteCompareOptions{}, AppearanceOptions{}, {camera, camera, true});
  EXPECT_EQ(comparison.prior_depth_frames, kFrames);
  EXPECT_EQ(comparison.current_depth_frames, kFrames);
  EXPECT_EQ(static_cast<int>(comparison.pairs.size()), kFrames);
  EXPECT_TRUE(comparison.changes.empty());
  // Poses the two patrols do not share (GPS fixes) give no depth.
  const RouteComparison apart =
      CompareRoutes(prior, current, {}, RouteCompareOptions{}, AppearanceOptions{}, {camera, camera, false});
  EXPECT_EQ(apart.prior_depth_frames + apart.current_depth_frames, 0);
}

// Each patrol's lens goes with its frames; poses from GPS fixes (metres of bias) or none give no depth.
TEST(RouteCompare, TheRouteCamerasCarryEachLensAndComparePosesOfOneWorldFrameOnly) {
  PatrolRecord prior, current;
  prior.camera = current.camera = CameraIntrinsics{229.0, 229.0, 187.5, 119.5, 376, 240};
  prior.distortion = {-0.28, 0.07, 0.0, 0.0};
  current.distortion = {-0.1, 0.0, 0.001, 0.0};
  prior.pose_source = kPosesFromStateEstimate;
  current.pose_source = kPosesFromFile;
  RouteCameras cameras = RouteCamerasOf(prior, current);
  EXPECT_TRUE(cameras.poses_comparable);
  EXPECT_EQ(cameras.prior_distortion, prior.distortion);
  EXPECT_EQ(cameras.current_distortion, current.distortion);
  EXPECT_EQ(cameras.current.fx, 229.0);
  current.pose_source = kPosesFromGps;
  EXPECT_FALSE(RouteCamerasOf(prior, current).poses_comparable);
  current.pose_source.clear();
  EXPECT_FALSE(RouteCamerasOf(prior, current).poses_comparable);
}

TEST(RouteCompare, AnObjectSeenFromSeveralFramesIsFoundWithTheirVotes) {
  const cv::Mat facade = Facade(4);
  cv::Mat changed = facade.clone();
  const cv::Rect object(300, 90, 60, 70);  // facade pixels: in frames 0-7 of the current route
  changed(object).setTo(35);
  cv::rectangle(changed, object, cv::Scalar(230), 3);
  const std::vector<RouteFrame> prior = Route(facade, 0, 1.0, 0.0);
  const std::vector<RouteFrame> current = Route(changed, 8, 1.0, 0.0);
  const RouteComparison comparison = CompareRoutes(prior, current, {}, RouteCompareOptions{}, AppearanceOptions{});
  EXPECT_EQ(static_cast<int>(comparison.pairs.size()), kFrames);  // without anchors, by thumbnails alone
  ASSERT_FALSE(comparison.changes.empty());
  std::size_t most_views = 0;
  for (const RouteChange& change : comparison.changes) {  // the object's outline and its inside may part
    EXPECT_TRUE(OnObject(comparison, change, 8, object.x, object.br().x, object));
    EXPECT_GT(change.score, 0.0);
    EXPECT_EQ(change.marked_share, 0.0);  // no poses, no depth
    std::set<int> pairs;
    for (const RouteChange::View& v : change.views) pairs.insert(v.pair);
    EXPECT_DOUBLE_EQ(change.confidence, RouteConfidence(change.score, 0.0, static_cast<int>(pairs.size())));
    most_views = std::max(most_views, change.views.size());
  }
  EXPECT_GE(most_views, 4u);
}

// Appearance and depth each vouch for a change; more views weigh more.
TEST(RouteCompare, AChangeIsDoubtedOnlyAsFarAsAppearanceAndDepthBothDoubtIt) {
  EXPECT_DOUBLE_EQ(RouteConfidence(0.5, 0.0, 1), 0.25);         // appearance alone, one view
  EXPECT_DOUBLE_EQ(RouteConfidence(0.5, 0.0, 3), 0.375);        // ... three views
  EXPECT_DOUBLE_EQ(RouteConfidence(-0.4, 0.8, 3), 0.6);         // depth alone: a score under 0 takes nothing
  EXPECT_DOUBLE_EQ(RouteConfidence(0.5, 0.5, 3), 0.75 * 0.75);  // both
  EXPECT_DOUBLE_EQ(RouteConfidence(1.7, 0.0, 1), 0.5);          // a score over 1 counts as 1
  EXPECT_DOUBLE_EQ(RouteConfidence(0.0, 0.0, 4), 0.0);
}

TEST(RouteCompare, ARegionInOneFrameOnlyIsNotReported) {
  const cv::Mat facade = Facade(5);
  std::vector<RouteFrame> current = Route(facade, 0, 1.0, 0.0);
  cv::Mat frame = cv::imdecode(current[6].jpeg, cv::IMREAD_GRAYSCALE);
  frame(cv::Rect(150, 80, 60, 60)).setTo(20);  // a passer-by in one frame
  cv::imencode(".jpg", frame, current[6].jpeg);
  RouteCompareOptions options;
  const RouteComparison voted = CompareRoutes(Route(facade, 0, 1.0, 0.0), current, {}, options, AppearanceOptions{});
  EXPECT_TRUE(voted.changes.empty());
  options.min_votes = 1;
  const RouteComparison single = CompareRoutes(Route(facade, 0, 1.0, 0.0), current, {}, options, AppearanceOptions{});
  ASSERT_FALSE(single.changes.empty());
  for (const RouteChange& change : single.changes) EXPECT_EQ(single.pairs[change.views[0].pair].current, 6);
}

// The second prior frame confirms a region when it finds one there too; where it does not show the region whole, it
// cannot confirm it, and the region is kept.
TEST(RouteCompare, ARegionIsDroppedOnlyWhereTheSecondPriorFrameShowsItAndFindsNothing) {
  AppearanceRegion left, right;
  left.current_box = cv::Rect(10, 100, 40, 40);
  right.current_box = cv::Rect(250, 100, 40, 40);
  AppearanceChange change;
  change.regions = {left, right};
  AppearanceChange second;  // its prior frame lands 100 px to the right: columns 100-475 of the current frame
  second.registered = true;
  second.homography = (cv::Mat_<double>(3, 3) << 1, 0, 100, 0, 1, 0, 0, 0, 1);
  const cv::Size size(kFrameWidth, kFrameHeight);
  AppearanceChange unconfirmed = change;
  KeepSeenFromBoth(second, size, 0.3, &unconfirmed);
  ASSERT_EQ(unconfirmed.regions.size(), 1u);  // the left one: the second prior frame does not show it
  EXPECT_EQ(unconfirmed.regions[0].current_box, left.current_box);
  ASSERT_EQ(unconfirmed.dropped.size(), 1u);
  EXPECT_EQ(unconfirmed.dropped[0].region.current_box, right.current_box);
  EXPECT_EQ(unconfirmed.dropped[0].reason, DropReason::kNotSeenFromSecondPrior);
  AppearanceRegion found;  // the second comparison found the right one too, a little off
  found.current_box = cv::Rect(260, 105, 40, 40);
  second.regions = {found};
  AppearanceChange confirmed = change;
  KeepSeenFromBoth(second, size, 0.3, &confirmed);
  EXPECT_EQ(confirmed.regions.size(), 2u);
  EXPECT_TRUE(confirmed.dropped.empty());
}

TEST(RouteCompare, OneThreadOrSeveralGiveTheSameComparison) {
  const cv::Mat facade = Facade(7);
  cv::Mat changed = facade.clone();
  changed(cv::Rect(420, 60, 50, 90)).setTo(40);
  // With poses, so each frame's depth is computed too.
  const std::vector<RouteFrame> prior = WithPoses(Route(facade, 0, 1.0, 0.0), 0),
                                current = WithPoses(Route(changed, 6, 0.9, 10.0), 6);
  const CameraIntrinsics camera{kFocalPx, kFocalPx, 187.5, 119.5, kFrameWidth, kFrameHeight};
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const RouteComparison one =
      CompareRoutes(prior, current, {}, RouteCompareOptions{}, AppearanceOptions{}, {camera, camera, true});
  cv::setNumThreads(std::max(2, threads));
  const RouteComparison several =
      CompareRoutes(prior, current, {}, RouteCompareOptions{}, AppearanceOptions{}, {camera, camera, true});
  cv::setNumThreads(threads);
  EXPECT_GT(one.current_depth_frames, 0);
  EXPECT_EQ(one.current_depth_frames, several.current_depth_frames);
  ASSERT_EQ(one.pairs.size(), several.pairs.size());
  for (std::size_t i = 0; i < one.pairs.size(); ++i) {
    EXPECT_EQ(one.pairs[i].prior, several.pairs[i].prior);
    ASSERT_EQ(one.pairs[i].appearance.regions.size(), several.pairs[i].appearance.regions.size());
    for (std::size_t r = 0; r < one.pairs[i].appearance.regions.size(); ++r) {
      EXPECT_EQ(one.pairs[i].appearance.regions[r].current_box, several.pairs[i].appearance.regions[r].current_box);
      EXPECT_EQ(one.pairs[i].appearance.regions[r].score, several.pairs[i].appearance.regions[r].score);
    }
  }
  ASSERT_FALSE(one.changes.empty());
  ASSERT_EQ(one.changes.size(), several.changes.size());
  for (std::size_t i = 0; i < one.changes.size(); ++i) EXPECT_EQ(one.changes[i].score, several.changes[i].score);
}

TEST(RouteCompare, WithoutFramesNothingIsCompared) {
  const RouteComparison comparison =
      CompareRoutes({}, Route(Facade(6), 0, 1.0, 0.0), {}, RouteCompareOptions{}, AppearanceOptions{});
  EXPECT_FALSE(comparison.compared);
  EXPECT_EQ(comparison.ComparedShare(), 0.0);
}

// The shared KITTI excerpt (51 frames at 10 Hz, forward motion along a road), flown twice: unchanged, and
// with a textured 120x100 object (a facade patch) pasted into frames 20-25 of the second flight.
const std::string kKittiImages = std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data/kitti_seq2/image_l";
constexpr int kKittiFrames = 51;

std::vector<RouteFrame> KittiRoute(const cv::Rect& object, int first, int last) {
  const cv::Mat patch = Facade(7)(cv::Rect(0, 0, object.width, object.height));
  std::vector<RouteFrame> route;
  for (int i = 0; i < kKittiFrames; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "/%06d.png", i);
    cv::Mat image = cv::imread(kKittiImages + name, cv::IMREAD_GRAYSCALE);
    if (i >= first && i <= last) patch.copyTo(image(object));
    RouteFrame f = AsRouteFrame(image, 80);
    f.timestamp_ns = SecondsToNs(0.1 * i);
    f.frame_index = i;
    route.push_back(std::move(f));
  }
  return route;
}

TEST(RouteCompare, KittiFlownTwiceGivesNoChangeAndAPastedObjectIsFound) {
  if (!std::filesystem::exists(kKittiImages)) GTEST_SKIP() << "shared KITTI excerpt not present";
  const cv::Rect object(560, 150, 120, 100);  // full-size pixels, above the road ahead
  const std::vector<RouteFrame> prior = KittiRoute(object, 0, -1);
  const std::vector<RouteAnchor> anchors = {{SecondsToNs(0.0), SecondsToNs(0.0)}, {SecondsToNs(5.0), SecondsToNs(5.0)}};
  const RouteComparison same = CompareRoutes(prior, prior, anchors, RouteCompareOptions{}, AppearanceOptions{});
  EXPECT_EQ(static_cast<int>(same.pairs.size()), kKittiFrames);
  EXPECT_TRUE(same.changes.empty()) << same.changes.size() << " changes";

  const RouteComparison changed =
      CompareRoutes(prior, KittiRoute(object, 20, 25), anchors, RouteCompareOptions{}, AppearanceOptions{});
  EXPECT_EQ(static_cast<int>(changed.pairs.size()), kKittiFrames);
  ASSERT_EQ(changed.changes.size(), 1u);
  EXPECT_GE(changed.changes[0].views.size(), 4u);
  const double scale = static_cast<double>(kFrameWidth) / 1241;  // KITTI's width
  const cv::Rect expected(cv::Point(object.tl()) * scale, cv::Point(object.br()) * scale);
  for (const RouteChange::View& v : changed.changes[0].views) {
    const RoutePair& pair = changed.pairs[v.pair];
    EXPECT_GE(pair.current, 20);
    EXPECT_LE(pair.current, 25);
    const cv::Rect& box = pair.appearance.regions[v.region].current_box;
    EXPECT_GE((box & expected).area(), 0.5 * std::min(box.area(), expected.area())) << box << " vs " << expected;
  }
}

// Real pairs of one unchanged scene (Debian's opencv-doc): an exposure change (leuven), a strong viewpoint change
// of a plane (graf) and an aerial view from elsewhere (aero). At the route frames' width, none may give a region,
// with both_ways or without.
class RealUnchangedPair : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(RealUnchangedPair, GivesNoRegion) {
  const std::string data = "/usr/share/doc/opencv-doc/examples/data/";
  if (!std::filesystem::exists(data + GetParam().first)) GTEST_SKIP() << "opencv-doc not installed";
  const auto view = [&](const char* name) { return RouteView(cv::imread(data + name, cv::IMREAD_GRAYSCALE), 95); };
  for (const bool both_ways : {false, true}) {  // with both_ways too
    AppearanceOptions options;
    options.both_ways = both_ways;
    const AppearanceChange change = DetectAppearanceChange(view(GetParam().first), view(GetParam().second), options);
    if (std::string(GetParam().first) == "leuvenA.jpg") {
      EXPECT_TRUE(change.registered);
    }
    if (!change.registered) continue;  // aero1/aero3 at this width: 5 inliers, not compared (nothing reported)
    EXPECT_TRUE(change.regions.empty()) << change.regions.size() << " regions (both_ways " << both_ways
                                        << "), the first at " << change.regions[0].current_box;
  }
}

INSTANTIATE_TEST_SUITE_P(OpencvDoc, RealUnchangedPair,
                         ::testing::Values(std::make_pair("leuvenA.jpg", "leuvenB.jpg"),
                                           std::make_pair("graf1.png", "graf3.png"),
                                           std::make_pair("graf3.png", "graf1.png"),
                                           std::make_pair("aero1.jpg", "aero3.jpg")));

// Real revisits of one unchanged room (the shared EuRoC pairs, 752x480, a MAV seen from two viewpoints), at the route
// frames' width, each pair both ways round: with both_ways, none gives a region. (With the defaults, left_img_3
// against left_img_2 gives two, on furniture and a wall seen with parallax: BENCHMARKS.md, "Appearance along the
// route".)
TEST(RouteCompare, RealEurocRevisitsGiveNoRegionWithBothWays) {
  const std::string folder = std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data/euroc_revisit_pairs/";
  if (!std::filesystem::exists(folder)) GTEST_SKIP() << "shared EuRoC pairs not present";
  const auto view = [&](int index) {
    return RouteView(cv::imread(folder + cv::format("left_img_%d.png", index), cv::IMREAD_GRAYSCALE), 80);
  };
  AppearanceOptions options;
  options.both_ways = true;
  for (const auto& [prior, current] : {std::pair(0, 1), std::pair(1, 0), std::pair(2, 3), std::pair(3, 2)}) {
    const AppearanceChange change = DetectAppearanceChange(view(prior), view(current), options);
    EXPECT_TRUE(change.registered) << prior << " -> " << current;
    EXPECT_TRUE(change.regions.empty()) << prior << " -> " << current << ": " << change.regions.size()
                                        << " regions, the first at " << change.regions[0].current_box;
  }
}

// Real change (Debian's opencv-doc, vtest.avi): a static camera over a square where people walk. Between frames 0
// and 400, three people left their place and three others came; their boxes at the route frames' width come from
// the video's median frame and were checked by eye. Compared both ways round, each pair has 6 people to find: with
// both_ways all 6 are, and every region, with or without it, lies on a person.
TEST(RouteCompare, RealPeopleThatLeftAndCameAreFoundWithBothWays) {
  const std::string video = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";
  cv::VideoCapture capture(video);
  if (!capture.isOpened()) GTEST_SKIP() << "opencv-doc's vtest.avi not installed or not decodable";
  std::vector<KeyFrameView> views;
  cv::Mat frame;
  for (int index = 0; index <= 400 && capture.read(frame); ++index) {
    if (index % 400 != 0) continue;
    cv::Mat grey;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    views.push_back(RouteView(grey, 95));
  }
  if (views.size() < 2) GTEST_SKIP() << "vtest.avi ended before frame 400";
  const std::vector<std::vector<cv::Rect>> people = {{{243, 80, 18, 36}, {122, 106, 19, 47}, {311, 116, 26, 46}},
                                                     {{287, 70, 17, 32}, {132, 96, 18, 47}, {334, 145, 32, 59}}};
  const auto on = [](const cv::Rect& region, const cv::Rect& person) {
    return (region & person).area() >= 0.3 * std::min(region.area(), person.area());
  };
  for (const bool both_ways : {false, true}) {
    AppearanceOptions options;
    options.both_ways = both_ways;
    for (int prior = 0; prior < 2; ++prior) {
      const AppearanceChange change = DetectAppearanceChange(views[prior], views[1 - prior], options);
      ASSERT_TRUE(change.registered);
      int found = 0;
      for (const auto& frame_people : people) {
        for (const cv::Rect& person : frame_people) {
          found += std::any_of(change.regions.begin(), change.regions.end(),
                               [&](const AppearanceRegion& r) { return on(r.current_box, person); });
        }
      }
      for (const AppearanceRegion& r : change.regions) {
        EXPECT_TRUE(
            std::any_of(people[0].begin(), people[0].end(), [&](const cv::Rect& p) { return on(r.current_box, p); }) ||
            std::any_of(people[1].begin(), people[1].end(), [&](const cv::Rect& p) { return on(r.current_box, p); }))
            << "a region off every person at " << r.current_box;
      }
      if (both_ways) {
        EXPECT_EQ(found, 6) << "frame " << 400 * prior << " as the prior";
      }
    }
  }
}

}  // namespace
}  // namespace patrolmap::change
