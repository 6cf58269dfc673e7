#include "patrolmap/change/route_compare.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <set>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/change/route_depth.h"

namespace patrolmap::change {
namespace {

const cv::Size kSignatureSize(32, 20);  // the thumbnail that ranks a frame's candidate partners

// A frame as a small thumbnail with zero mean and unit norm: the dot product of two is their normalised
// correlation, free of exposure.
cv::Mat Signature(const cv::Mat& grey) {
  cv::Mat small, floats;
  if (grey.empty()) return cv::Mat::zeros(kSignatureSize, CV_32F);
  cv::resize(grey, small, kSignatureSize, 0, 0, cv::INTER_AREA);
  small.convertTo(floats, CV_32F);
  floats -= cv::mean(floats)[0];
  const double norm = cv::norm(floats);
  if (norm > 0.0) floats /= norm;
  return floats;
}

double Seconds(TimestampNs ns) { return static_cast<double>(ns) * 1e-9; }

// Per frame: whether it repeats the frame before (a key frame kept at an interval frame's time): it is neither
// compared nor a vote of its own.
std::vector<bool> Repeats(const std::vector<RouteFrame>& route) {
  std::vector<bool> repeats(route.size(), false);
  for (std::size_t i = 1; i < route.size(); ++i) repeats[i] = route[i].timestamp_ns == route[i - 1].timestamp_ns;
  return repeats;
}

// The prior times a current frame's partner is expected at: the same time offset (prior - current) as the two
// anchors nearest in time, and as the previous aligned pair (`previous_offset_s`).
std::vector<double> PredictedTimes(double current_s, const std::vector<RouteAnchor>& anchors,
                                   std::optional<double> previous_offset_s) {
  std::vector<std::pair<double, double>> by_distance;  // (|time apart|, predicted prior time)
  for (const RouteAnchor& a : anchors) {
    by_distance.emplace_back(std::abs(Seconds(a.current_ns) - current_s),
                             Seconds(a.prior_ns) + current_s - Seconds(a.current_ns));
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<double> times;
  for (std::size_t i = 0; i < by_distance.size() && i < 2; ++i) times.push_back(by_distance[i].second);
  if (previous_offset_s) times.push_back(current_s + *previous_offset_s);
  return times;
}

// The prior frames within the window of a predicted time (all of them without a prediction), the
// `max_candidates` most alike first.
std::vector<int> Candidates(const std::vector<double>& predicted, const std::vector<RouteFrame>& prior,
                            const std::vector<cv::Mat>& prior_signatures, const cv::Mat& signature,
                            const RouteCompareOptions& options) {
  std::vector<std::pair<double, int>> ranked;
  for (std::size_t p = 0; p < prior.size(); ++p) {
    const double t = Seconds(prior[p].timestamp_ns);
    const bool near = predicted.empty() || std::any_of(predicted.begin(), predicted.end(), [&](double centre) {
                        return std::abs(t - centre) <= options.search_window_s;
                      });
    if (near && !prior_signatures[p].empty())
      ranked.emplace_back(-signature.dot(prior_signatures[p]), static_cast<int>(p));
  }
  const std::size_t keep = std::min(ranked.size(), static_cast<std::size_t>(options.max_candidates));
  std::partial_sort(ranked.begin(), ranked.begin() + keep, ranked.end());
  std::vector<int> candidates;
  for (std::size_t i = 0; i < keep; ++i) candidates.push_back(ranked[i].second);
  return candidates;
}

// Overlap of two boxes as a share of the smaller one.
double OverlapOfSmaller(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double smaller = std::min(a.area(), b.area());
  return smaller > 0.0 ? (a & b).area() / smaller : 0.0;
}

constexpr double kNearlyMostInliers = 0.8;

// The share of a `size` image that the prior image (of `prior_size`) covers through the homography.
double Coverage(const cv::Mat& current_from_prior, const cv::Size& prior_size, const cv::Size& size) {
  const std::vector<cv::Point2f> corners = {
      {0.0f, 0.0f},
      {static_cast<float>(prior_size.width), 0.0f},
      {static_cast<float>(prior_size.width), static_cast<float>(prior_size.height)},
      {0.0f, static_cast<float>(prior_size.height)}};
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(corners, mapped, current_from_prior);
  const std::vector<cv::Point2f> image = {{0.0f, 0.0f},
                                          {static_cast<float>(size.width), 0.0f},
                                          {static_cast<float>(size.width), static_cast<float>(size.height)},
                                          {0.0f, static_cast<float>(size.height)}};
  std::vector<cv::Point2f> overlap;
  if (!cv::isContourConvex(mapped)) return 0.0;
  const float area = cv::intersectConvexConvex(mapped, image, overlap);
  return size.area() > 0 ? area / size.area() : 0.0;
}

// A current frame's partner and the runner-up, registered.
struct Alignment {
  int current = -1;
  std::vector<std::pair<Registration, int>> registered;  // (registration, prior frame), the partner first
};

// Registers the candidates onto the current frame `c`; the partner is, of those with nearly the most
// inliers (alike in registration), the one covering most of the frame: the nearest viewpoint (least
// parallax). False when no candidate registers.
bool AlignFrame(int c, const std::vector<int>& candidates, const std::vector<KeyFrameView>& prior_views,
                const std::vector<KeyFrameView>& current_views, const AppearanceOptions& appearance,
                Alignment* alignment) {
  std::vector<std::pair<Registration, int>>& registered = alignment->registered;
  for (const int p : candidates) {
    Registration r = Register(prior_views[p], current_views[c], appearance);
    if (r.inliers >= appearance.min_inliers && !r.current_from_prior.empty()) registered.emplace_back(std::move(r), p);
  }
  if (registered.empty()) return false;
  int most = 0;
  for (const auto& r : registered) most = std::max(most, r.first.inliers);
  const cv::Size size = current_views[c].image.size();
  const auto rank = [&](const std::pair<Registration, int>& r) {
    const bool near_most = r.first.inliers >= kNearlyMostInliers * most;
    return std::make_pair(near_most,
                          near_most ? Coverage(r.first.current_from_prior, prior_views[r.second].image.size(), size)
                                    : static_cast<double>(r.first.inliers));
  };
  std::stable_sort(registered.begin(), registered.end(),
                   [&](const auto& a, const auto& b) { return rank(a) > rank(b); });
  registered.resize(std::min<std::size_t>(registered.size(), 2));
  alignment->current = c;
  return true;
}

// Compares the aligned frame with its partner; a region must be found against the runner-up too.
RoutePair ComparePair(const Alignment& alignment, const std::vector<KeyFrameView>& prior_views,
                      const std::vector<KeyFrameView>& current_views, const RouteCompareOptions& options,
                      const AppearanceOptions& appearance, const ChangeLocationOptions& location) {
  RoutePair pair;
  const auto& [registration, prior] = alignment.registered[0];
  pair.prior = prior;
  pair.current = alignment.current;
  const KeyFrameView& current = current_views[pair.current];
  const auto parallax = [&](int prior_frame, const Registration& r, const cv::Mat& marks) -> ParallaxPredictor {
    return [&prior_views, &current, &r, &options, prior_frame, marks](const cv::Rect& box) {
      return PredictParallax(prior_views[prior_frame], current, r.current_from_prior, marks, box, options.depth);
    };
  };
  const cv::Mat marks = VisibilityChange(prior_views[prior], current, options.depth);
  pair.appearance = CompareRegistered(prior_views[prior], current, registration, appearance, marks,
                                      parallax(prior, registration, marks));
  if (alignment.registered.size() > 1 && !pair.appearance.regions.empty()) {
    const auto& [second_registration, second_prior] = alignment.registered[1];
    const cv::Mat second_marks = VisibilityChange(prior_views[second_prior], current, options.depth);
    const AppearanceChange second =
        CompareRegistered(prior_views[second_prior], current, second_registration, appearance, second_marks,
                          parallax(second_prior, second_registration, second_marks));
    if (second.registered) {
      KeepSeenFromBoth(second, prior_views[second_prior].image.size(), options.min_overlap, &pair.appearance);
    }
  }
  for (AppearanceRegion& region : pair.appearance.regions)
    region.world = PointFromDepth(current, region.current_box, location);
  return pair;
}

cv::Rect2d MapBox(const cv::Rect& box, const cv::Mat& homography) {
  const std::vector<cv::Point2f> corners = {cv::Point2f(box.x, box.y), cv::Point2f(box.x + box.width, box.y),
                                            cv::Point2f(box.x + box.width, box.y + box.height),
                                            cv::Point2f(box.x, box.y + box.height)};
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(corners, mapped, homography);
  return cv::boundingRect(mapped);
}

// Whether the prior frame of `comparison` (of `prior_size`, registered onto the current one) shows all of `box`.
bool Covers(const AppearanceChange& comparison, const cv::Size& prior_size, const cv::Rect& box) {
  const cv::Rect2d in_prior = MapBox(box, comparison.homography.inv());
  return (in_prior & cv::Rect2d(0.0, 0.0, prior_size.width, prior_size.height)) == in_prior;
}

int Find(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

// Links the regions of consecutive aligned pairs that show the same thing: the earlier box carried into the
// later current frame overlaps the later box.
void LinkConsecutive(const RouteComparison& comparison, const std::vector<KeyFrameView>& current_views,
                     const std::vector<int>& next, const std::vector<int>& first_node,
                     const RouteCompareOptions& options, const AppearanceOptions& appearance,
                     std::vector<int>* parent) {
  for (std::size_t i = 0; i + 1 < comparison.pairs.size(); ++i) {
    const RoutePair &a = comparison.pairs[i], &b = comparison.pairs[i + 1];
    if (a.appearance.regions.empty() || b.appearance.regions.empty() || b.current != next[a.current]) continue;
    const Registration step = Register(current_views[a.current], current_views[b.current], appearance);
    if (step.inliers < appearance.min_inliers || step.current_from_prior.empty()) continue;
    for (std::size_t ra = 0; ra < a.appearance.regions.size(); ++ra) {
      const cv::Rect2d carried = MapBox(a.appearance.regions[ra].current_box, step.current_from_prior);
      for (std::size_t rb = 0; rb < b.appearance.regions.size(); ++rb) {
        if (OverlapOfSmaller(carried, b.appearance.regions[rb].current_box) < options.min_overlap) continue;
        (*parent)[Find(parent, first_node[i] + static_cast<int>(ra))] =
            Find(parent, first_node[i + 1] + static_cast<int>(rb));
      }
    }
  }
}

// The chains of linked regions over at least min_votes pairs, as changes.
std::vector<RouteChange> Vote(const RouteComparison& comparison, const std::vector<KeyFrameView>& current_views,
                              const std::vector<int>& next, const RouteCompareOptions& options,
                              const AppearanceOptions& appearance) {
  std::vector<int> first_node;  // per pair: the node of its first region
  int nodes = 0;
  for (const RoutePair& pair : comparison.pairs) {
    first_node.push_back(nodes);
    nodes += static_cast<int>(pair.appearance.regions.size());
  }
  std::vector<int> parent(nodes);
  std::iota(parent.begin(), parent.end(), 0);
  LinkConsecutive(comparison, current_views, next, first_node, options, appearance, &parent);
  std::map<int, RouteChange> chains;  // by root, so the changes come in route order
  for (std::size_t i = 0; i < comparison.pairs.size(); ++i) {
    for (std::size_t r = 0; r < comparison.pairs[i].appearance.regions.size(); ++r) {
      const int root = Find(&parent, first_node[i] + static_cast<int>(r));
      chains[root].views.push_back({static_cast<int>(i), static_cast<int>(r)});
    }
  }
  std::vector<RouteChange> changes;
  for (auto& [root, change] : chains) {
    std::vector<int> pairs;
    for (const RouteChange::View& v : change.views) pairs.push_back(v.pair);
    const int votes = static_cast<int>(std::set<int>(pairs.begin(), pairs.end()).size());
    if (votes < options.min_votes) continue;
    int largest = 0;
    double score = 0.0, marked = 0.0;
    for (std::size_t k = 0; k < change.views.size(); ++k) {
      const auto region = [&](std::size_t j) -> const AppearanceRegion& {
        return comparison.pairs[change.views[j].pair].appearance.regions[change.views[j].region];
      };
      score += region(k).score;
      marked += region(k).marked_share;
      if (region(k).area_px > region(largest).area_px) largest = static_cast<int>(k);
    }
    change.best = largest;
    change.score = score / change.views.size();
    change.marked_share = marked / change.views.size();
    change.confidence = RouteConfidence(change.score, change.marked_share, votes);
    changes.push_back(std::move(change));
  }
  std::sort(changes.begin(), changes.end(),
            [](const RouteChange& a, const RouteChange& b) { return a.views.front().pair < b.views.front().pair; });
  return changes;
}

// Depth for one route's frames (route_depth.h): each frame with a pose is matched with the frames with poses before
// and after it. Depth is computed when a block of pairs needs it and released when the next block does not, so a long
// flight's depth images are never all held at once. A frame's depth is its own: the same whatever the threads and
// blocks.
class RouteDepths {
 public:
  RouteDepths(const std::vector<RouteFrame>& route, const std::vector<bool>& repeats, const CameraIntrinsics& camera,
              const Distortion& distortion, const RouteDepthOptions& options, std::vector<KeyFrameView>* views)
      : route_(route), options_(options), views_(views), held_(route.size(), false), given_(route.size(), false) {
    for (std::size_t k = 0; k < route.size(); ++k) {
      if (!repeats[k] && route[k].pose && !(*views)[k].image.empty()) usable_.push_back(static_cast<int>(k));
    }
    if (!camera.valid()) usable_.clear();
    for (const int k : usable_) {  // one lens per size of frame (a patrol's route frames share one)
      const cv::Size size = (*views)[k].image.size();
      if (lenses_.count({size.width, size.height}) > 0) continue;
      CameraIntrinsics scaled = camera.Scaled(static_cast<double>(size.width) / camera.width);
      scaled.width = size.width;
      scaled.height = size.height;
      lenses_.emplace(std::make_pair(size.width, size.height), depth::Lens(scaled, distortion));
    }
  }

  // Gives each frame of `wanted` its depth (where it can have any) and releases every other frame's.
  void Keep(const std::set<int>& wanted) {
    std::vector<int> missing;  // positions in usable_
    for (std::size_t i = 0; i < usable_.size(); ++i) {
      const int k = usable_[i];
      if (wanted.count(k) == 0) {
        (*views_)[k].depth.release();
        held_[k] = false;
      } else if (!held_[k]) {
        missing.push_back(static_cast<int>(i));
      }
    }
    cv::parallel_for_(cv::Range(0, static_cast<int>(missing.size())), [&](const cv::Range& range) {
      for (int m = range.start; m < range.end; ++m) Compute(missing[m]);
    });
    for (const int i : missing) {
      held_[usable_[i]] = true;
      if (!(*views_)[usable_[i]].depth.empty()) given_[usable_[i]] = true;
    }
  }

  // The frames given depth so far.
  int frames_given() const { return static_cast<int>(std::count(given_.begin(), given_.end(), true)); }

 private:
  void Compute(int i) const {
    std::vector<RouteNeighbour> neighbours;
    for (const int j : {i - 1, i + 1}) {
      if (j < 0 || j >= static_cast<int>(usable_.size())) continue;
      neighbours.push_back({(*views_)[usable_[j]].image, *route_[usable_[j]].pose});
    }
    KeyFrameView& view = (*views_)[usable_[i]];
    const depth::Lens& lens = lenses_.at({view.image.cols, view.image.rows});
    AddMotionDepth(neighbours, lens, *route_[usable_[i]].pose, options_, &view);
  }

  const std::vector<RouteFrame>& route_;
  const RouteDepthOptions options_;
  std::vector<KeyFrameView>* views_;
  std::vector<int> usable_;                            // the frames with a pose and an image, in route order
  std::map<std::pair<int, int>, depth::Lens> lenses_;  // by frame width and height
  std::vector<bool> held_, given_;
};

// The component-wise median of `points` (not empty).
Eigen::Vector3d Median(std::vector<Eigen::Vector3d> points) {
  Eigen::Vector3d median;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Eigen::Vector3d& p : points) values.push_back(p[axis]);
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    median[axis] = values[values.size() / 2];
  }
  return median;
}

// Where `change` stands (RouteChange::location): its views' depth points, else their rays triangulated where the
// poses lie in one world frame, else its best view's bearing; nothing without a pose or a camera.
ChangeLocation LocateRouteChange(const RouteComparison& comparison, const RouteChange& change,
                                 const std::vector<RouteFrame>& current, const std::vector<KeyFrameView>& current_views,
                                 const RouteCameras& cameras, const ChangeLocationOptions& options) {
  ChangeLocation location;
  std::vector<Eigen::Vector3d> points;
  std::vector<Bearing> rays;
  for (std::size_t k = 0; k < change.views.size(); ++k) {
    const RoutePair& pair = comparison.pairs[change.views[k].pair];
    const AppearanceRegion& region = pair.appearance.regions[change.views[k].region];
    if (region.world) points.push_back(*region.world);
    const RouteFrame& frame = current[pair.current];
    if (!frame.pose || !cameras.current.valid() || current_views[pair.current].image.empty()) continue;
    rays.push_back(BearingThrough(cameras.current, cameras.current_distortion, current_views[pair.current].image.cols,
                                  *frame.pose, region.current_box));
    if (static_cast<int>(k) == change.best || rays.size() == 1) location.bearing = rays.back();
  }
  if (!points.empty()) {
    location.by = LocatedBy::kDepth;
    location.point = Median(points);
    return location;
  }
  if (rays.empty()) return location;
  const std::optional<Eigen::Vector3d> met =
      cameras.poses_comparable ? Triangulate(rays, options) : std::optional<Eigen::Vector3d>();
  location.by = met ? LocatedBy::kTriangulated : LocatedBy::kBearing;
  if (met) location.point = *met;
  return location;
}

// Aligned pairs compared at a time: with depth, the depth of at most this many current frames and their prior
// frames is held (0.36 MB a 376x240 frame). The results do not depend on it.
constexpr std::size_t kPairsPerBlock = 32;

// Compares the aligned pairs, block by block, the frames of each block given depth first when `depths` are given.
void CompareBlocks(const std::vector<Alignment>& alignments, const std::vector<KeyFrameView>& prior_views,
                   const std::vector<KeyFrameView>& current_views, const RouteCompareOptions& options,
                   const AppearanceOptions& appearance, const ChangeLocationOptions& location,
                   RouteDepths* prior_depths, RouteDepths* current_depths, std::vector<RoutePair>* pairs) {
  pairs->resize(alignments.size());
  for (std::size_t start = 0; start < alignments.size(); start += kPairsPerBlock) {
    const std::size_t end = std::min(alignments.size(), start + kPairsPerBlock);
    if (prior_depths != nullptr && current_depths != nullptr) {
      std::set<int> prior_wanted, current_wanted;
      for (std::size_t i = start; i < end; ++i) {
        current_wanted.insert(alignments[i].current);
        for (const auto& registered : alignments[i].registered) prior_wanted.insert(registered.second);
      }
      prior_depths->Keep(prior_wanted);
      current_depths->Keep(current_wanted);
    }
    cv::parallel_for_(cv::Range(static_cast<int>(start), static_cast<int>(end)), [&](const cv::Range& range) {
      for (int i = range.start; i < range.end; ++i) {
        (*pairs)[i] = ComparePair(alignments[i], prior_views, current_views, options, appearance, location);
      }
    });
  }
  if (prior_depths != nullptr && current_depths != nullptr) {
    prior_depths->Keep({});
    current_depths->Keep({});
  }
}

}  // namespace

double RouteConfidence(double score, double marked_share, int votes) {
  const double doubt = (1.0 - std::clamp(score, 0.0, 1.0)) * (1.0 - std::clamp(marked_share, 0.0, 1.0));
  return (1.0 - doubt) * votes / (votes + 1.0);
}

void KeepSeenFromBoth(const AppearanceChange& second, const cv::Size& second_size, double min_overlap,
                      AppearanceChange* change) {
  std::vector<AppearanceRegion> kept;
  for (AppearanceRegion& r : change->regions) {
    const bool seen = std::any_of(second.regions.begin(), second.regions.end(), [&](const AppearanceRegion& s) {
      return OverlapOfSmaller(r.current_box, s.current_box) >= min_overlap;
    });
    if (seen || !Covers(second, second_size, r.current_box)) {
      kept.push_back(std::move(r));
    } else {
      change->dropped.push_back({std::move(r), DropReason::kNotSeenFromSecondPrior});
    }
  }
  change->regions = std::move(kept);
}

double RouteComparison::ComparedShare() const {
  return current_frames > 0 ? static_cast<double>(pairs.size()) / current_frames : 0.0;
}

KeyFrameView RouteFrameView(const RouteFrame& frame, int max_features) {
  KeyFrameView view;
  if (!frame.jpeg.empty()) view.image = cv::imdecode(frame.jpeg, cv::IMREAD_GRAYSCALE);
  if (view.image.empty()) return view;
  std::vector<cv::KeyPoint> keypoints;
  cv::SIFT::create(max_features)->detectAndCompute(view.image, cv::noArray(), keypoints, view.descriptors);
  cv::KeyPoint::convert(keypoints, view.points);
  return view;
}

RouteCameras RouteCamerasOf(const PatrolRecord& prior, const PatrolRecord& current) {
  const auto comparable = [](const std::string& source) { return !source.empty() && source != kPosesFromGps; };
  RouteCameras cameras;
  cameras.prior = prior.camera, cameras.current = current.camera;
  cameras.poses_comparable = comparable(prior.pose_source) && comparable(current.pose_source);
  cameras.prior_distortion = prior.distortion, cameras.current_distortion = current.distortion;
  return cameras;
}

RouteComparison CompareRoutes(const std::vector<RouteFrame>& prior, const std::vector<RouteFrame>& current,
                              const std::vector<RouteAnchor>& anchors, const RouteCompareOptions& options,
                              const AppearanceOptions& appearance, const RouteCameras& cameras,
                              const ChangeLocationOptions& location) {
  RouteComparison comparison;
  const std::vector<bool> prior_repeats = Repeats(prior), current_repeats = Repeats(current);
  comparison.current_frames = static_cast<int>(std::count(current_repeats.begin(), current_repeats.end(), false));
  if (prior.empty() || current.empty()) return comparison;
  comparison.compared = true;
  std::vector<KeyFrameView> prior_views(prior.size()), current_views(current.size());
  std::vector<cv::Mat> prior_signatures(prior.size());
  // Each frame's features, each pair's comparison on its own: the same whatever the threads.
  cv::parallel_for_(cv::Range(0, static_cast<int>(prior.size() + current.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const bool is_prior = i < static_cast<int>(prior.size());
      const std::size_t k = is_prior ? i : i - prior.size();
      if (is_prior ? prior_repeats[k] : current_repeats[k]) continue;
      if (is_prior) {
        prior_views[k] = RouteFrameView(prior[k], options.max_features);
        prior_signatures[k] = Signature(prior_views[k].image);
      } else {
        current_views[k] = RouteFrameView(current[k], options.max_features);
      }
    }
  });
  std::vector<Alignment> alignments;
  for (std::size_t c = 0; c < current.size(); ++c) {  // in order: each predicts the next one's partner
    if (current_repeats[c]) continue;
    const Alignment* previous = alignments.empty() ? nullptr : &alignments.back();
    const std::vector<double> predicted = PredictedTimes(
        Seconds(current[c].timestamp_ns), anchors,
        previous != nullptr ? std::optional<double>(Seconds(prior[previous->registered[0].second].timestamp_ns) -
                                                    Seconds(current[previous->current].timestamp_ns))
                            : std::nullopt);
    const std::vector<int> candidates =
        Candidates(predicted, prior, prior_signatures, Signature(current_views[c].image), options);
    Alignment alignment;
    if (AlignFrame(static_cast<int>(c), candidates, prior_views, current_views, appearance, &alignment)) {
      alignments.push_back(std::move(alignment));
    }
  }
  if (options.depth.enabled && cameras.poses_comparable) {
    RouteDepths prior_depths(prior, prior_repeats, cameras.prior, cameras.prior_distortion, options.depth,
                             &prior_views);
    RouteDepths current_depths(current, current_repeats, cameras.current, cameras.current_distortion, options.depth,
                               &current_views);
    CompareBlocks(alignments, prior_views, current_views, options, appearance, location, &prior_depths, &current_depths,
                  &comparison.pairs);
    comparison.prior_depth_frames = prior_depths.frames_given();
    comparison.current_depth_frames = current_depths.frames_given();
  } else {
    CompareBlocks(alignments, prior_views, current_views, options, appearance, location, nullptr, nullptr,
                  &comparison.pairs);
  }
  std::vector<int> next(current.size(), -1);  // per frame: the next frame that is no repeat
  for (int c = static_cast<int>(current.size()) - 2; c >= 0; --c)
    next[c] = current_repeats[c + 1] ? next[c + 1] : c + 1;
  comparison.changes = Vote(comparison, current_views, next, options, appearance);
  for (RouteChange& change : comparison.changes) {
    change.location = LocateRouteChange(comparison, change, current, current_views, cameras, location);
  }
  return comparison;
}

}  // namespace patrolmap::change
