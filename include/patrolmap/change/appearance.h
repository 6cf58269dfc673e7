// Appearance change between the key frames of one place seen on two patrols:
// the prior key frame is registered onto the current one by a homography
// from matched features, the lighting difference is compensated twice (a
// global gain and offset fitted over the overlap, and a local mean/contrast
// normalisation), and pixels that differ under both, by more than their best
// match within a small shift (parallax), form the changed regions:
// connected, above a minimum size, each with a score and its box in both
// images. A lighting-only change differs in the global but not in the local
// comparison, so it yields no region. A region whose features (prior and
// current, inside its box) mostly still match between the two key frames
// shows the same things seen from elsewhere (parallax off the registered
// plane), not a change, and is dropped; featureless regions are kept.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/change/options.h"
#include "patrolmap/core/types.h"
#include "patrolmap/depth/lens.h"

namespace patrolmap::change {

// One key frame: its image (grey) and features, whose coordinates are
// `feature_scale` times the image's (e.g. features found at 188 px width on a
// 160 px thumbnail: 188 / 160).
struct KeyFrameView {
  cv::Mat image;
  std::vector<cv::Point2f> points;  // feature positions
  cv::Mat descriptors;              // float, 8-bit or packed 4-bit rows (vocab/descriptors.h)
  double feature_scale = 1.0;
  // Route frames only, when their depth is known (route_depth.h): depth [m] on the image's grid (CV_32F, 0 =
  // unknown), the camera and its lens at the image's size, its pose, and the range error per squared metre of depth.
  cv::Mat depth;
  depth::Lens lens;
  CameraPoseSample pose;
  double range_sigma_per_m2 = 0.0;
};

struct AppearanceRegion {
  cv::Rect current_box;  // in the current key frame
  cv::Rect prior_box;    // the same region in the prior key frame
  int area_px = 0;
  double score = 0.0;                    // mean structure change in the region (1 - contrast-structure term)
  double marked_share = 0.0;             // share of its pixels that depth marked as changed (`also_changed`)
  int prior_features = 0;                // prior features inside the region's box (mapped into the current frame)
  int unmatched_prior_features = 0;      // ... of which no current feature matches (they support the change)
  int current_features = 0;              // current features inside the box
  int unmatched_current_features = 0;    // ... of which no prior feature matches
  std::optional<Eigen::Vector3d> world;  // where the current frame's depth puts its centre (route frames with depth)
};

// Why a region of changed pixels was not kept, in the order the tests run.
enum class DropReason {
  kThin,                    // thinner than min_side_fraction: a seam at a depth edge
  kAtPriorEdge,             // within edge_margin_px of where the registered prior frame ends
  kFeaturesStillMatch,      // under min_unmatched_share of its features lost their match (parallax)
  kShiftedCopy,             // the prior shows its content a few pixels off (parallax_search_px; parallax)
  kNotSeenFromSecondPrior,  // along the route: a second prior frame shows no region there
};
const char* DropReasonName(DropReason reason);  // snake case, as in the evaluation's JSON

struct DroppedRegion {
  AppearanceRegion region;
  DropReason reason = DropReason::kThin;
};

struct AppearanceChange {
  bool registered = false;
  int matches = 0, inliers = 0;
  double gain = 1.0, offset = 0.0;        // current ~ gain * prior + offset over the overlap
  double compared_fraction = 0.0;         // share of the current image the registered prior covers
  cv::Mat homography;                     // current_from_prior, image pixels (CV_64F 3x3)
  std::vector<AppearanceRegion> regions;  // largest first
  // The regions that were dropped, and why (those under min_area_fraction are not listed): `eval` tells from
  // them where a change that was not reported was lost.
  std::vector<DroppedRegion> dropped;
};

// Whether a changed region is kept by its features: a region without features is; one with features only
// when at least `min_unmatched_share` of them (prior and current together) found no match in the other
// key frame. Features that still match show the same things seen from elsewhere (parallax).
bool KeepsUnmatchedShare(const AppearanceRegion& region, const AppearanceOptions& options);

// The prior key frame registered onto the current one: ratio-test matches (query = current) and the homography
// fitted to them by RANSAC (empty when it failed).
struct Registration {
  std::vector<cv::DMatch> matches;
  int inliers = 0;
  cv::Mat current_from_prior;  // image pixels, CV_64F 3x3
  // Further planes (AppearanceOptions::max_planes), each fitted to the matches no plane before explains.
  std::vector<cv::Mat> more_planes;
};
Registration Register(const KeyFrameView& prior, const KeyFrameView& current, const AppearanceOptions& options);

// Where the registered prior shows a region's content if nothing changed there, as depth tells it (route_depth.h):
// the shift from the region's box in the current image [pixels], and how far from it the content may lie.
struct ParallaxPrediction {
  cv::Point2d shift;
  int slack_px = 0;
};
// Per region, by its box in the current image: the prediction, or none where depth does not tell.
using ParallaxPredictor = std::function<std::optional<ParallaxPrediction>(const cv::Rect& current_box)>;

// The changed regions of a registered pair (none when it has fewer than min_inliers inliers). `also_changed`
// (CV_8U on the current image, 255 = changed; may be empty) holds pixels known changed by other means (the
// visibility test of route_depth.h): they join the changed pixels before regions form. `parallax` (may be empty)
// narrows the shifted-copy test: where it predicts a region's shift, and the box so shifted lies in the image, the
// region is a shifted copy only if the prior shows its content within the slack of that shift, so a thing that
// moved a few pixels stays a change; elsewhere the test searches as far as the options say.
AppearanceChange CompareRegistered(const KeyFrameView& prior, const KeyFrameView& current,
                                   const Registration& registration, const AppearanceOptions& options,
                                   const cv::Mat& also_changed = cv::Mat(),
                                   const ParallaxPredictor& parallax = nullptr);

// Register, then CompareRegistered.
AppearanceChange DetectAppearanceChange(const KeyFrameView& prior, const KeyFrameView& current,
                                        const AppearanceOptions& options);

}  // namespace patrolmap::change
