#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

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

// A textured scene, its view after a lighting change, and SIFT features of both.
struct Pair {
  KeyFrameView prior, current;
};

KeyFrameView Describe(const cv::Mat& image) {
  KeyFrameView view;
  view.image = image;
  std::vector<cv::KeyPoint> keypoints;
  cv::SIFT::create(500)->detectAndCompute(image, cv::noArray(), keypoints, view.descriptors);
  cv::KeyPoint::convert(keypoints, view.points);
  return view;
}

cv::Mat Scene(int seed) {
  cv::Mat image(120, 160, CV_8UC1);
  cv::RNG rng(seed);
  image.setTo(120);
  for (int i = 0; i < 90; ++i) {
    const cv::Point a(rng.uniform(0, 160), rng.uniform(0, 120));
    cv::rectangle(image, a, a + cv::Point(rng.uniform(3, 18), rng.uniform(3, 18)), cv::Scalar(rng.uniform(0, 255)),
                  cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.7);
  return image;
}

cv::Mat Relit(const cv::Mat& image, double gain, double gamma, double shift_px) {
  cv::Mat moved, out;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, shift_px, 0, 1, 0);
  cv::warpAffine(image, moved, m, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  moved.convertTo(out, CV_32F, 1.0 / 255);
  cv::pow(out, gamma, out);
  out.convertTo(out, CV_8U, 255 * gain);
  return out;
}

TEST(Appearance, LightingOnlyGivesNoRegion) {
  const cv::Mat scene = Scene(1);
  const AppearanceChange change =
      DetectAppearanceChange(Describe(scene), Describe(Relit(scene, 0.8, 1.3, 3.0)), AppearanceOptions{});
  ASSERT_TRUE(change.registered);
  EXPECT_GT(change.inliers, 30);
  EXPECT_TRUE(change.regions.empty());
  EXPECT_NEAR(change.homography.at<double>(0, 2), 3.0, 0.5);
}

TEST(Appearance, AnAddedObjectIsARegionInBothImages) {
  const cv::Mat scene = Scene(2);
  cv::Mat current = Relit(scene, 1.1, 0.9, -2.0);
  const cv::Rect object(60, 40, 26, 22);
  current(object).setTo(30);
  cv::rectangle(current, object, cv::Scalar(220), 2);
  const AppearanceChange change = DetectAppearanceChange(Describe(scene), Describe(current), AppearanceOptions{});
  ASSERT_TRUE(change.registered);
  ASSERT_FALSE(change.regions.empty());
  const AppearanceRegion& region = change.regions[0];
  EXPECT_GT((region.current_box & object).area(), 0.6 * object.area());
  EXPECT_LT(region.current_box.area(), 2.0 * object.area());
  EXPECT_NEAR(region.prior_box.x, region.current_box.x + 2, 2);  // the prior view is 2 px to the right
  EXPECT_GT(region.score, 0.0);
  EXPECT_GT(region.unmatched_prior_features, 0);  // the prior texture under the object no longer matches
  EXPECT_EQ(region.marked_share, 0.0);            // nothing marked it
}

// Pixels another witness (depth's visibility test) marked are counted in the region they join.
TEST(Appearance, ARegionCountsTheShareOfItsPixelsDepthMarked) {
  const cv::Mat scene = Scene(2);
  cv::Mat current = scene.clone();
  const cv::Rect object(60, 40, 26, 22);
  current(object).setTo(30);
  cv::rectangle(current, object, cv::Scalar(220), 2);
  const KeyFrameView prior_view = Describe(scene), current_view = Describe(current);
  const Registration registration = Register(prior_view, current_view, AppearanceOptions{});
  const auto marked_share = [&](const cv::Rect& marked) {
    cv::Mat marks = cv::Mat::zeros(scene.size(), CV_8U);
    marks(marked).setTo(255);
    marks(cv::Rect(4, 4, 6, 6)).setTo(255);  // a speck far off, too small to be a region of its own
    const AppearanceChange change =
        CompareRegistered(prior_view, current_view, registration, AppearanceOptions{}, marks);
    EXPECT_EQ(change.regions.size(), 1u);
    if (change.regions.empty()) return -1.0;
    const AppearanceRegion& region = change.regions[0];
    EXPECT_LE(region.marked_share * region.area_px, cv::countNonZero(marks(region.current_box)) + 0.5);  // its own
    return region.marked_share;
  };
  const double whole = marked_share(object), left = marked_share(cv::Rect(60, 40, 13, 22));
  EXPECT_GT(whole, 0.7);
  EXPECT_LE(whole, 1.0);
  EXPECT_GT(left, 0.3);  // the flat inside was not found by appearance alone: marked, it joins the region
  EXPECT_LT(left, whole);
}

// A region that only depth marked, along the frame's bottom row where nothing changed: its structure change is
// small and never below 0 (the window there reaches past the frame).
TEST(Appearance, TheStructureChangeAtTheFramesBorderStaysWithinZeroAndOne) {
  const cv::Mat scene = Scene(3);
  const KeyFrameView prior_view = Describe(scene), current_view = Describe(Relit(scene, 0.8, 1.3, 0.0));
  AppearanceOptions options;
  options.min_unmatched_share = 0.0;     // the features there still match: nothing changed ...
  options.max_shifted_similarity = 1.0;  // ... and the prior shows the same content there
  const Registration registration = Register(prior_view, current_view, options);
  cv::Mat marks = cv::Mat::zeros(scene.size(), CV_8U);
  marks(cv::Rect(30, scene.rows - 12, 100, 12)).setTo(255);
  const AppearanceChange change = CompareRegistered(prior_view, current_view, registration, options, marks);
  ASSERT_EQ(change.regions.size(), 1u);
  EXPECT_GE(change.regions[0].score, 0.0);
  EXPECT_LT(change.regions[0].score, 0.2);
  EXPECT_GT(change.regions[0].marked_share, 0.9);
}

// A scene whose middle is bare ground, a gentle gradient, and the same scene with a thin dark object (a person)
// standing on it. An object that came is found whichever way the pixels are searched. One that left is found with
// both_ways, both the pixels and the shift test: searched one way only, the bare ground now in its place is found
// beside it in the prior, its outline shrinks to nothing, and what is left counts as the prior shown shifted.
TEST(Appearance, AnObjectThatLeftIsFoundWhenThePairIsComparedBothWays) {
  cv::Mat bare = Scene(4);
  const cv::Rect ground(40, 20, 80, 80), object(76, 40, 8, 30);
  for (int x = 0; x < ground.width; ++x) bare(ground).col(x).setTo(150 + x / 4);
  cv::Mat with_object = bare.clone();
  with_object(object).setTo(40);
  cv::GaussianBlur(with_object, with_object, cv::Size(3, 3), 0.7);
  const auto found = [&](const cv::Mat& prior, const cv::Mat& current, bool both_ways) {
    AppearanceOptions options;
    options.both_ways = both_ways;
    const AppearanceChange change = DetectAppearanceChange(Describe(prior), Describe(current), options);
    EXPECT_TRUE(change.registered);
    return std::count_if(change.regions.begin(), change.regions.end(), [&](const AppearanceRegion& r) {
      return (r.current_box & object).area() > 0.5 * object.area();
    });
  };
  EXPECT_EQ(found(bare, with_object, false), 1);  // came
  EXPECT_EQ(found(bare, with_object, true), 1);
  EXPECT_EQ(found(with_object, bare, true), 1);  // left
  EXPECT_EQ(found(with_object, bare, false), 0);
}

// Where the registered prior frame ends, what it shows is cut off or off the registered plane (graf1/graf3 in
// route_compare_test): with edge_margin_px a region there is dropped, and one inside is kept. The current view
// shows the scene 2 px further right than the prior, so the prior ends 2 px inside the current's right border.
TEST(Appearance, ARegionWhereThePriorFrameEndsIsDroppedWithAnEdgeMargin) {
  const cv::Mat scene = Scene(2);
  cv::Mat current = Relit(scene, 1.1, 0.9, -2.0);
  const cv::Rect inside(60, 40, 26, 22), at_edge(134, 80, 26, 22);
  for (const cv::Rect& object : {inside, at_edge}) {
    current(object).setTo(30);
    cv::rectangle(current, object, cv::Scalar(220), 2);
  }
  AppearanceOptions options;
  const auto found = [&](const cv::Rect& object) {
    const AppearanceChange change = DetectAppearanceChange(Describe(scene), Describe(current), options);
    EXPECT_TRUE(change.registered);
    return std::any_of(change.regions.begin(), change.regions.end(),
                       [&](const AppearanceRegion& r) { return (r.current_box & object).area() > 0; });
  };
  options.edge_margin_px = 0;
  EXPECT_TRUE(found(inside));
  EXPECT_TRUE(found(at_edge));
  options.edge_margin_px = 1;
  EXPECT_TRUE(found(inside));
  EXPECT_FALSE(found(at_edge));
}

// A scene with a textured area, and the current view of it in which the block kNearerBlock of that area is seen 7 px
// off the rest (a nearer facade, off the plane of the rest).
const cv::Rect kNearerBlock(50, 30, 60, 60);
void NearerBlock(cv::Mat* scene, cv::Mat* current) {
  *scene = Scene(5);
  cv::Mat texture(60, 80, CV_8UC1);
  cv::setRNGSeed(8);  // the same texture whatever test ran before
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.2);
  texture.copyTo((*scene)(cv::Rect(40, 30, 80, 60)));
  *current = scene->clone();
  (*scene)(kNearerBlock - cv::Point(7, 0)).copyTo((*current)(kNearerBlock));
}

// Options that keep every region the pixels form: neither the feature test nor the shift test drops one.
AppearanceOptions WithoutRegionTests() {
  AppearanceOptions options;
  options.min_unmatched_share = 0.0;
  options.max_shifted_similarity = 1.1;
  return options;
}

TEST(Appearance, ARegionWhoseFeaturesStillMatchIsParallaxNotChange) {
  // A textured block of the scene seen 7 px off the rest (a nearer facade, off the registered plane): its
  // pixels differ beyond the search radius, but its features match their prior selves.
  cv::Mat scene, current;
  NearerBlock(&scene, &current);
  const AppearanceOptions keep_all = WithoutRegionTests();
  const AppearanceChange all = DetectAppearanceChange(Describe(scene), Describe(current), keep_all);
  ASSERT_TRUE(all.registered);
  ASSERT_FALSE(all.regions.empty());  // the registration cannot fit both planes: pixels differ somewhere
  for (const AppearanceRegion& r : all.regions) {
    EXPECT_GT(r.prior_features + r.current_features, 0);
    EXPECT_LT(r.unmatched_prior_features + r.unmatched_current_features, 0.5 * (r.prior_features + r.current_features));
  }
  const AppearanceChange defaults = DetectAppearanceChange(Describe(scene), Describe(current), AppearanceOptions{});
  EXPECT_TRUE(defaults.regions.empty());
  ASSERT_FALSE(defaults.dropped.empty());  // they are listed as dropped, with the test that dropped them
  for (const DroppedRegion& d : defaults.dropped) {
    EXPECT_TRUE(d.reason == DropReason::kFeaturesStillMatch || d.reason == DropReason::kShiftedCopy ||
                d.reason == DropReason::kThin)
        << DropReasonName(d.reason);
  }
  EXPECT_TRUE(std::any_of(defaults.dropped.begin(), defaults.dropped.end(),
                          [](const DroppedRegion& d) { return d.reason == DropReason::kFeaturesStillMatch; }));
  // Each test alone drops them too: the features still match, and the content is there a few pixels off.
  AppearanceOptions features_only = keep_all, shift_only = keep_all;
  features_only.min_unmatched_share = 0.5;
  shift_only.max_shifted_similarity = AppearanceOptions{}.max_shifted_similarity;
  EXPECT_TRUE(DetectAppearanceChange(Describe(scene), Describe(current), features_only).regions.empty());
  EXPECT_LT(DetectAppearanceChange(Describe(scene), Describe(current), shift_only).regions.size(), all.regions.size());
}

// The same nearer block, 7 px off the rest: one homography registers either the block or the rest, and the other
// differs. A second plane, fitted to the matches the first leaves, registers that too: with max_planes 2 no region
// is left, even with both region tests off.
TEST(Appearance, ASecondPlaneRegistersANearerBlock) {
  cv::Mat scene, current;
  NearerBlock(&scene, &current);
  const AppearanceOptions one_plane = WithoutRegionTests();
  const KeyFrameView prior = Describe(scene), now = Describe(current);
  const Registration single = Register(prior, now, one_plane);
  EXPECT_TRUE(single.more_planes.empty());
  EXPECT_FALSE(CompareRegistered(prior, now, single, one_plane).regions.empty());
  AppearanceOptions two_planes = one_plane;
  two_planes.max_planes = 2;
  const Registration both = Register(prior, now, two_planes);
  ASSERT_EQ(both.more_planes.size(), 1u);
  const AppearanceChange change = CompareRegistered(prior, now, both, two_planes);
  ASSERT_TRUE(change.registered);
  EXPECT_TRUE(change.regions.empty());
}

// A scene and its view with `block` seen 18 px further left than the rest (a nearer facade, or background beside a
// nearer edge): the prior shows the block's content 18 px off horizontally.
struct ShiftedBlock {
  cv::Mat scene = Scene(5), current = scene.clone();
  cv::Rect block{60, 36, 40, 40};
  ShiftedBlock() { scene(block + cv::Point(18, 0)).copyTo(current(block)); }
  long RegionsOnBlock(const AppearanceChange& change) const {
    return std::count_if(change.regions.begin(), change.regions.end(),
                         [&](const AppearanceRegion& r) { return (r.current_box & block).area() > 0; });
  }
};

// The shift is beyond parallax_search_px but within horizontal_parallax_search_px, so the shift test drops the block;
// searched only 8 px, it is kept.
TEST(Appearance, ContentThePriorShowsFurtherAlongTheRowIsParallax) {
  const ShiftedBlock shifted;
  const cv::Mat &scene = shifted.scene, &current = shifted.current;
  const cv::Rect& block = shifted.block;
  AppearanceOptions options;
  options.min_unmatched_share = 0.0;  // only the shift test decides
  const auto on_block = [&](const AppearanceChange& change) { return shifted.RegionsOnBlock(change); };
  const AppearanceChange defaults = DetectAppearanceChange(Describe(scene), Describe(current), options);
  ASSERT_TRUE(defaults.registered);
  EXPECT_EQ(on_block(defaults), 0);
  EXPECT_TRUE(std::any_of(defaults.dropped.begin(), defaults.dropped.end(), [&](const DroppedRegion& d) {
    return d.reason == DropReason::kShiftedCopy && (d.region.current_box & block).area() > 0;
  }));
  options.horizontal_parallax_search_px = 8;
  EXPECT_GT(on_block(DetectAppearanceChange(Describe(scene), Describe(current), options)), 0);
}

// The same block where depth predicts its parallax (route_depth.h): predicted 18 px off (or within the slack of it),
// it is the shifted copy it looks; predicted on the registered plane, or 9 px off, the prior does not show it there
// and it is a change (a thing that moved); predicted where the image ends, the wide search decides as before.
TEST(Appearance, APredictedParallaxNarrowsTheShiftedCopySearch) {
  const ShiftedBlock shifted;
  AppearanceOptions options;
  options.min_unmatched_share = 0.0;  // only the shift test decides
  const KeyFrameView prior_view = Describe(shifted.scene), current_view = Describe(shifted.current);
  const Registration registration = Register(prior_view, current_view, options);
  const auto on_block = [&](const cv::Point2d& shift) {
    const ParallaxPredictor predictor = [&](const cv::Rect&) {
      return std::optional<ParallaxPrediction>(ParallaxPrediction{shift, 4});
    };
    const AppearanceChange change =
        CompareRegistered(prior_view, current_view, registration, options, cv::Mat(), predictor);
    EXPECT_TRUE(change.registered);
    return shifted.RegionsOnBlock(change);
  };
  EXPECT_EQ(on_block({18.0, 0.0}), 0);
  EXPECT_EQ(on_block({15.0, 2.0}), 0);
  EXPECT_GT(on_block({0.0, 0.0}), 0);
  EXPECT_GT(on_block({9.0, 0.0}), 0);
  EXPECT_EQ(on_block({-100.0, 0.0}), 0);
}

TEST(Appearance, ARegionIsKeptAtItsUnmatchedShareAndDroppedBelowIt) {
  AppearanceOptions options;  // min_unmatched_share 0.5
  AppearanceRegion region;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));  // no features: nothing says parallax
  region.prior_features = 6, region.current_features = 4;
  region.unmatched_prior_features = 3, region.unmatched_current_features = 2;  // 5 of 10: exactly the share
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  region.unmatched_current_features = 1;  // 4 of 10
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  region.unmatched_prior_features = 0, region.unmatched_current_features = 3;  // 3 of 10: both sides count
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 0.3;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 0.0;  // keeps every region, even one whose features all match
  region.unmatched_current_features = 0;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
  options.min_unmatched_share = 1.0;  // keeps only regions where nothing matches
  region.unmatched_prior_features = 6, region.unmatched_current_features = 3;
  EXPECT_FALSE(KeepsUnmatchedShare(region, options));
  region.unmatched_current_features = 4;
  EXPECT_TRUE(KeepsUnmatchedShare(region, options));
}

// Matches alone do not register a pair: the homography needs min_inliers inliers. Two halves of the scene
// moved apart (two planes) match everywhere, but one homography fits one half; with min_inliers between
// the two counts the pair is not registered and yields no region.
TEST(Appearance, APairNeedsItsInliersNotOnlyItsMatches) {
  const cv::Mat prior = Scene(5);
  cv::Mat current = prior.clone();
  const cv::Rect right(80, 0, 80, 120);
  Scene(5)(right - cv::Point(20, 0)).copyTo(current(right));  // the right half shows what lay 20 px left
  const AppearanceChange loose = DetectAppearanceChange(Describe(prior), Describe(current), AppearanceOptions{});
  ASSERT_TRUE(loose.registered);
  ASSERT_LT(loose.inliers, 0.8 * loose.matches) << "one homography should not fit both halves";
  AppearanceOptions strict;
  strict.min_inliers = (loose.inliers + loose.matches) / 2;
  const AppearanceChange change = DetectAppearanceChange(Describe(prior), Describe(current), strict);
  EXPECT_EQ(change.matches, loose.matches);
  EXPECT_FALSE(change.registered);
  EXPECT_TRUE(change.regions.empty());
}

TEST(Appearance, UnrelatedImagesAreNotRegistered) {
  const AppearanceChange change = DetectAppearanceChange(Describe(Scene(3)), Describe(Scene(4)), AppearanceOptions{});
  EXPECT_FALSE(change.registered);
  EXPECT_TRUE(change.regions.empty());
  EXPECT_FALSE(DetectAppearanceChange(KeyFrameView{}, KeyFrameView{}, AppearanceOptions{}).registered);
}

}  // namespace
}  // namespace patrolmap::change
