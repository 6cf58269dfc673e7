// Appearance change along the whole route: every frame a patrol kept along its route
// (PatrolRecord::route) is aligned to the frame of the prior patrol's route that shows the same place, and
// every aligned pair is compared (DetectAppearanceChange). A region is reported when consecutive aligned
// pairs agree on it.
//
// Alignment. Loop closures between the two flights are anchors: each ties a prior time to a current time. A
// current frame's partner is searched among the prior frames within `search_window_s` of the times its
// nearest anchors predict (the same time offset) and of the time the previous aligned frame's partner
// predicts; without anchors, among all prior frames. The candidate whose features register onto the frame
// with the most homography inliers (at least the appearance stage's min_inliers) is its partner.
//
// Voting. A region of one aligned pair agrees with one of the next pair (the next current frame) when its box,
// carried into that frame by the homography between the two current frames, overlaps it by `min_overlap` of
// the smaller box. Chains of agreeing regions over at least `min_votes` pairs are the changes; a lone region is
// a fluke of one view (a reflection, an alignment error, a passer-by) and is dropped.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/change_location.h"
#include "patrolmap/change/options.h"
#include "patrolmap/core/patrol_data.h"

namespace patrolmap::change {

struct RouteAnchor {
  TimestampNs prior_ns = 0, current_ns = 0;  // the same place on the two flights
};

// One current route frame and the prior route frame aligned to it, compared.
struct RoutePair {
  int prior = -1, current = -1;  // indices into the two routes
  AppearanceChange appearance;
};

// One region seen in consecutive aligned pairs.
struct RouteChange {
  struct View {
    int pair = -1, region = -1;  // RouteComparison::pairs[pair].appearance.regions[region]
  };
  std::vector<View> views;    // in time order, one per agreeing pair
  int best = 0;               // index into views: the largest region
  double score = 0.0;         // mean structure change over the views
  double marked_share = 0.0;  // mean share of the views' pixels that depth marked (AppearanceRegion::marked_share)
  double confidence = 0.0;    // RouteConfidence(score, marked_share, the pairs the views come from)
  // Where it stands: its views' depth (the median of their points), else their rays triangulated (poses in one
  // world frame only), else its best view's bearing (change_location.h). The change detector may place it on the
  // current patrol's evidence grid instead of triangulating or giving a bearing.
  ChangeLocation location;
};

struct RouteComparison {
  bool compared = false;   // both patrols kept frames along their routes
  int current_frames = 0;  // frames the current patrol kept
  // Frames given depth from their neighbours (RouteCameras; 0 with change.route.depth off or without poses).
  int prior_depth_frames = 0, current_depth_frames = 0;
  std::vector<RoutePair> pairs;  // the aligned pairs, in the current route's order
  std::vector<RouteChange> changes;
  // The share of the current route that was aligned and compared.
  double ComparedShare() const;
};

// A route change's confidence, in [0, 1]: appearance (the mean structure `score`, clamped to [0, 1]) and depth (the
// `marked_share`) are two witnesses, and the change is doubted only as far as both doubt it; weighed by v / (v + 1) for
// the `votes` (pairs) that agreed. A change that depth marked and that appearance barely shows (a score near 0)
// keeps the confidence depth gives it.
double RouteConfidence(double score, double marked_share, int votes);

// Keeps the regions of `change` that a comparison of the same current frame with a second prior frame (of
// `second_size`) also found (a region overlapping by `min_overlap` of the smaller box): what differs only from one
// viewpoint is parallax. A region the second prior frame does not show whole cannot be confirmed and is kept. The
// others move to change->dropped (kNotSeenFromSecondPrior).
void KeepSeenFromBoth(const AppearanceChange& second, const cv::Size& second_size, double min_overlap,
                      AppearanceChange* change);

// The cameras of the two patrols' route frames (PatrolRecord::camera, at the log's resolution) and their lenses'
// distortion (PatrolRecord::distortion; route frames are kept raw), and whether the two patrols' poses lie in one
// world frame. With change.route.depth on and such poses, each route frame with a pose
// that a compared pair uses gets depth from the frames before and after it in its patrol (route_depth.h), and each
// compared pair is also tested by visibility.
struct RouteCameras {
  CameraIntrinsics prior, current;
  bool poses_comparable = false;
  Distortion prior_distortion{}, current_distortion{};
};

// The route cameras of two patrols. Their poses count as lying in one world frame when both come from a state
// estimate, a pose topic or a pose file: a GPS fix's bias (metres) would put one patrol's surfaces where the other saw
// through.
RouteCameras RouteCamerasOf(const PatrolRecord& prior, const PatrolRecord& current);

// The route frame decoded (grey), with its SIFT features; feature_scale 1.
KeyFrameView RouteFrameView(const RouteFrame& frame, int max_features);

RouteComparison CompareRoutes(const std::vector<RouteFrame>& prior, const std::vector<RouteFrame>& current,
                              const std::vector<RouteAnchor>& anchors, const RouteCompareOptions& options,
                              const AppearanceOptions& appearance, const RouteCameras& cameras = RouteCameras(),
                              const ChangeLocationOptions& location = ChangeLocationOptions());

}  // namespace patrolmap::change
