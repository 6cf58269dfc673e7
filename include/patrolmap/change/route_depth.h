// Depth along the route: a route frame with a pose gets depth by semi-global matching against the frames
// before and after it in its own patrol (motion stereo; depth::StereoDepth with the pair's relative pose as its
// calibration; depth/motion_stereo.h). Both frames come from one flight, so they share the light, and depth tells what
// brightness cannot: a small face lit otherwise from a small object.
//
// Two patrols' frames with depth are then compared by visibility: a current surface that the prior camera saw
// through (its depth along that ray lies well beyond the surface) is new, and a prior surface the current camera
// sees through is gone. Both need the two patrols' poses in one world frame.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/options.h"
#include "patrolmap/core/types.h"
#include "patrolmap/depth/lens.h"
#include "patrolmap/depth/motion_stereo.h"

namespace patrolmap::change {

// Another frame of the same patrol (grey, the route frame's size), matched against a route frame for its depth.
using RouteNeighbour = depth::MotionFrame;

// Gives `view` (a route frame decoded, seen through `lens` at its own size from `pose`) depth from its
// neighbours: each one standing far enough, across the optical axis (RouteDepthOptions), is matched as a stereo pair.
// Where two give depth they must agree within the matching's range errors (repeated texture, a brick wall, matches
// a wrong period at a depth that depends on the baseline) and are averaged; elsewhere the one depth is kept. False,
// and `view` left without depth, when no neighbour gives any. A distorting lens is undone in the matching; the depth
// comes back on the raw image's grid.
bool AddMotionDepth(const std::vector<RouteNeighbour>& neighbours, const depth::Lens& lens,
                    const CameraPoseSample& pose, const RouteDepthOptions& options, KeyFrameView* view);

// The pixels of `current` (CV_8U, 255 = changed) where one patrol's surface stands in the space the other patrol
// saw through; empty when either view has no depth.
cv::Mat VisibilityChange(const KeyFrameView& prior, const KeyFrameView& current, const RouteDepthOptions& options);

// Where the prior view, registered onto the current one by `current_from_prior`, shows the content of the current
// view's `box` if nothing changed there: each pixel of the box with depth is put in space, seen from the prior camera
// and carried by the homography; the shift is the median over them, its slack `parallax_slack_px`. None where either
// view has no depth, `marks` (VisibilityChange's) hold under `parallax_min_marked_share` of the box (nothing tells
// that the geometry changed, and shade on unchanged surfaces must still find its wide shifted copy), the current view
// knows the depth of under `parallax_known_share` of the box, or most of its points fall outside the prior camera's
// view.
std::optional<ParallaxPrediction> PredictParallax(const KeyFrameView& prior, const KeyFrameView& current,
                                                  const cv::Mat& current_from_prior, const cv::Mat& marks,
                                                  const cv::Rect& box, const RouteDepthOptions& options);

}  // namespace patrolmap::change
