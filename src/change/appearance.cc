#include "patrolmap/change/appearance.h"

#include <algorithm>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/vocab/descriptors.h"

namespace patrolmap::change {
namespace {

cv::Mat AsFloat(const cv::Mat& descriptors) {
  cv::Mat floats;
  vocab::Expanded(descriptors).convertTo(floats, CV_32F);
  return floats;
}

// Ratio-test matches prior -> current (query = current).
std::vector<cv::DMatch> Match(const KeyFrameView& prior, const KeyFrameView& current, double ratio) {
  std::vector<cv::DMatch> good;
  if (prior.descriptors.rows < 2 || current.descriptors.rows < 2) return good;
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_L2).knnMatch(AsFloat(current.descriptors), AsFloat(prior.descriptors), knn, 2);
  for (const auto& pair : knn) {
    if (pair.size() == 2 && pair[0].distance < ratio * pair[1].distance) good.push_back(pair[0]);
  }
  return good;
}

// current ~ gain * prior + offset, least squares over the overlap, refitted on the pixels within 2.5 sigma.
void FitLighting(const cv::Mat& prior, const cv::Mat& current, const cv::Mat& mask, double* gain, double* offset) {
  std::vector<cv::Point> points;
  cv::findNonZero(mask, points);
  std::vector<char> keep(points.size(), 1);
  *gain = 1.0, *offset = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!keep[i]) continue;
      const double x = prior.at<float>(points[i]), y = current.at<float>(points[i]);
      n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    const double denominator = n * sxx - sx * sx;
    if (n < 10 || denominator <= 1e-9) return;
    *gain = (n * sxy - sx * sy) / denominator;
    *offset = (sy - *gain * sx) / n;
    double squared = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double r = current.at<float>(points[i]) - (*gain * prior.at<float>(points[i]) + *offset);
      squared += r * r;
    }
    const double sigma = std::sqrt(squared / points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double r = current.at<float>(points[i]) - (*gain * prior.at<float>(points[i]) + *offset);
      keep[i] = std::abs(r) < 2.5 * sigma;
    }
  }
}

constexpr double kC2 = (0.03 * 255) * (0.03 * 255);  // SSIM's stabiliser: flat pairs count as alike

// Local mean and variance over a Gaussian window.
void Moments(const cv::Mat& image, double sigma, cv::Mat* mean, cv::Mat* variance) {
  cv::Mat squares;
  cv::GaussianBlur(image, *mean, cv::Size(), sigma);
  cv::GaussianBlur(image.mul(image), squares, cv::Size(), sigma);
  *variance = cv::max(squares - mean->mul(*mean), 0.0);
}

void Shift(const cv::Mat& image, int dx, int dy, cv::Mat* shifted) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(image, *shifted, m, image.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
}

// Per pixel, the best contrast-structure term of SSIM (over a Gaussian window) between `a` and `b` shifted by
// up to `radius` pixels (parallax): 1 where the two have the same local pattern whatever their local gain,
// offset and an edge's polarity (a face lit the other way), near 0 where they differ. The windows' means and
// variances of `b` are shifted with it rather than recomputed.
cv::Mat BestStructure(const cv::Mat& a, const cv::Mat& b, int radius, double sigma) {
  cv::Mat ma, va, mb, vb;
  Moments(a, sigma, &ma, &va);
  Moments(b, sigma, &mb, &vb);
  va += kC2 / 2;
  vb += kC2 / 2;
  cv::Mat best, bs, mbs, vbs, ab, denominator;
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      Shift(b, dx, dy, &bs);
      Shift(mb, dx, dy, &mbs);
      Shift(vb, dx, dy, &vbs);
      cv::GaussianBlur(a.mul(bs), ab, cv::Size(), sigma);
      cv::sqrt(va.mul(vbs), denominator);
      const cv::Mat value = (cv::abs(ab - ma.mul(mbs)) + kC2 / 2) / denominator;
      best = best.empty() ? value : cv::Mat(cv::max(best, value));
    }
  }
  // Within a frame the term is at most 1. At its border, b's moments shifted (replicated) and the product's window
  // (reflected) disagree and the term can exceed it, which would read as less than no change.
  return cv::min(best, 1.0);
}

// Per pixel, the smallest absolute difference between `a` and `b` shifted by up to `radius` pixels (parallax).
cv::Mat SmallestDifference(const cv::Mat& a, const cv::Mat& b, int radius) {
  cv::Mat best, shifted;
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      Shift(b, dx, dy, &shifted);
      const cv::Mat value = cv::abs(a - shifted);
      best = best.empty() ? value : cv::Mat(cv::min(best, value));
    }
  }
  return best;
}

// Per pixel, the difference (after the gain and offset) and the structure change (1 - BestStructure) between
// the current image and the registered prior, the current window searched for in the prior within
// search_radius_px. With both_ways, each is the larger of that and the prior's window searched for in the
// current image: searched one way only, the background that replaced an object that left is found beside the
// object in the prior, and the object's outline shrinks to nothing, while an object that came keeps it.
void ComparePixels(const cv::Mat& current, const cv::Mat& warped, double gain, double offset,
                   const AppearanceOptions& options, cv::Mat* difference, cv::Mat* structure_change) {
  const int r = options.search_radius_px;
  const double sigma = options.structure_sigma_px;
  const cv::Mat compensated = warped * gain + offset;
  *difference = SmallestDifference(current, compensated, r);
  *structure_change = 1.0 - BestStructure(current, warped, r, sigma);
  if (!options.both_ways) return;
  *difference = cv::max(*difference, SmallestDifference(compensated, current, r));
  const cv::Mat prior_way = 1.0 - BestStructure(warped, current, r, sigma);
  *structure_change = cv::max(*structure_change, prior_way);
}

// Fits up to max_planes - 1 more homographies, each to the matches (`from` -> `to`) that no plane before
// explains; a plane needs min_inliers of them. `explained` holds the first plane's inliers.
std::vector<cv::Mat> FitMorePlanes(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                   std::vector<unsigned char> explained, const AppearanceOptions& options) {
  std::vector<cv::Mat> planes;
  for (int plane = 1; plane < options.max_planes; ++plane) {
    std::vector<cv::Point2f> rest_from, rest_to;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < from.size(); ++i) {
      if (explained[i]) continue;
      rest_from.push_back(from[i]);
      rest_to.push_back(to[i]);
      index.push_back(i);
    }
    if (static_cast<int>(index.size()) < std::max(4, options.min_inliers)) break;
    std::vector<unsigned char> inlier;
    cv::Mat h = cv::findHomography(rest_from, rest_to, cv::RANSAC, options.inlier_threshold_px, inlier, 2000, 0.999);
    if (h.empty() || cv::countNonZero(inlier) < options.min_inliers) break;
    for (std::size_t k = 0; k < index.size(); ++k) explained[index[k]] |= inlier[k];
    planes.push_back(h);
  }
  return planes;
}

// The prior image carried onto the current one's `size` by `current_from_prior`, and where it lands (eroded by
// `margin` pixels: the comparisons there need that much of it around).
void WarpPrior(const cv::Mat& prior, const cv::Mat& current_from_prior, const cv::Size& size, int margin,
               cv::Mat* warped, cv::Mat* mask) {
  cv::warpPerspective(prior, *warped, current_from_prior, size, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::warpPerspective(cv::Mat(prior.size(), CV_8U, cv::Scalar(255)), *mask, current_from_prior, size,
                      cv::INTER_NEAREST);
  cv::erode(*mask, *mask, cv::Mat(), cv::Point(-1, -1), margin);
}

cv::Rect PriorBox(const cv::Rect& box, const cv::Mat& current_from_prior, const cv::Size& prior_size) {
  std::vector<cv::Point2f> corners = {box.tl(),
                                      {static_cast<float>(box.br().x), static_cast<float>(box.y)},
                                      box.br(),
                                      {static_cast<float>(box.x), static_cast<float>(box.br().y)}};
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(corners, mapped, current_from_prior.inv());
  return cv::boundingRect(mapped) & cv::Rect(0, 0, prior_size.width, prior_size.height);
}

// The best normalised cross-correlation (free of gain and offset) of image `a`'s `box` with image `b` shifted by
// `centre` and then up to `across` pixels horizontally and `radius` vertically: near 1 when the region of the current
// image shows what the registered prior showed a little further on (parallax off the registered plane, or background
// the prior shows beside a nearer edge that hides it here). With both_ways it must hold the other way too: the
// background that replaced an object that left is found beside the object in the prior, but not the object in
// the current image.
double ShiftedSimilarity(const cv::Mat& a, const cv::Mat& b, const cv::Rect& box, const cv::Point& centre, int across,
                         int radius) {
  const cv::Rect image(0, 0, a.cols, a.rows);
  const cv::Rect search =
      cv::Rect(box.x + centre.x - across, box.y + centre.y - radius, box.width + 2 * across, box.height + 2 * radius) &
      image;
  if (box.width < 3 || box.height < 3 || search.width < box.width || search.height < box.height) return 0.0;
  cv::Mat scores;
  cv::matchTemplate(b(search), a(box), scores, cv::TM_CCOEFF_NORMED);
  double best = 0.0;
  cv::minMaxLoc(scores, nullptr, &best);
  return best;
}

// Whether the registered prior (through any of `warps`) shows the content of `current`'s `box` a little off
// (ShiftedSimilarity): near the predicted shift where there is one and the box so shifted lies in the image, else
// within the options' search.
bool ShowsShiftedCopy(const cv::Mat& current, const std::vector<cv::Mat>& warps, const cv::Rect& box,
                      const std::optional<ParallaxPrediction>& predicted, const AppearanceOptions& options) {
  cv::Point centre(0, 0);
  int across = std::max(options.parallax_search_px, options.horizontal_parallax_search_px);
  int radius = options.parallax_search_px;
  if (predicted) {
    const cv::Point shift(static_cast<int>(std::lround(predicted->shift.x)),
                          static_cast<int>(std::lround(predicted->shift.y)));
    const int slack = predicted->slack_px;
    const cv::Rect reach(box.x + shift.x - slack, box.y + shift.y - slack, box.width + 2 * slack,
                         box.height + 2 * slack);
    if ((reach & cv::Rect(0, 0, current.cols, current.rows)) == reach) centre = shift, across = radius = slack;
  }
  const auto shows = [&](const cv::Mat& a, const cv::Mat& b, const cv::Point& at) {
    return ShiftedSimilarity(a, b, box, at, across, radius) > options.max_shifted_similarity;
  };
  return std::any_of(warps.begin(), warps.end(), [&](const cv::Mat& w) {
    return shows(current, w, centre) && (!options.both_ways || shows(w, current, -centre));
  });
}

}  // namespace

// Per label, whether the region comes within `margin` pixels of where the registered prior frame ends inside the
// current one (all false when margin is 0). The current frame's own border does not count: objects there are
// seen again from the next route frames.
std::vector<bool> TouchingEdge(const cv::Mat& labels, int count, const cv::Mat& compared, int margin) {
  std::vector<bool> touching(count, false);
  if (margin <= 0) return touching;
  cv::Mat inner;
  cv::erode(compared, inner, cv::Mat(), cv::Point(-1, -1), margin);
  for (int y = 0; y < labels.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    const std::uint8_t* in = inner.ptr<std::uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (label[x] > 0 && in[x] == 0) touching[label[x]] = true;
    }
  }
  return touching;
}

const char* DropReasonName(DropReason reason) {
  switch (reason) {
    case DropReason::kThin: return "thin";
    case DropReason::kAtPriorEdge: return "at_prior_edge";
    case DropReason::kFeaturesStillMatch: return "features_still_match";
    case DropReason::kShiftedCopy: return "shifted_copy";
    case DropReason::kNotSeenFromSecondPrior: return "not_seen_from_second_prior";
  }
  return "unknown";
}

bool KeepsUnmatchedShare(const AppearanceRegion& region, const AppearanceOptions& options) {
  const int features = region.prior_features + region.current_features;
  const int unmatched = region.unmatched_prior_features + region.unmatched_current_features;
  return features == 0 || unmatched >= options.min_unmatched_share * features;
}

Registration Register(const KeyFrameView& prior, const KeyFrameView& current, const AppearanceOptions& options) {
  Registration registration;
  registration.matches = Match(prior, current, options.ratio);
  if (static_cast<int>(registration.matches.size()) < std::max(4, options.min_inliers)) return registration;
  std::vector<cv::Point2f> from, to;
  for (const cv::DMatch& m : registration.matches) {
    from.push_back(prior.points[m.trainIdx] / prior.feature_scale);
    to.push_back(current.points[m.queryIdx] / current.feature_scale);
  }
  std::vector<unsigned char> inlier;
  cv::Mat h = cv::findHomography(from, to, cv::RANSAC, options.inlier_threshold_px, inlier, 2000, 0.999);
  registration.inliers = h.empty() ? 0 : cv::countNonZero(inlier);
  if (h.empty()) return registration;
  registration.current_from_prior = h;
  registration.more_planes = FitMorePlanes(from, to, inlier, options);
  return registration;
}

AppearanceChange DetectAppearanceChange(const KeyFrameView& prior, const KeyFrameView& current,
                                        const AppearanceOptions& options) {
  return CompareRegistered(prior, current, Register(prior, current, options), options);
}

AppearanceChange CompareRegistered(const KeyFrameView& prior, const KeyFrameView& current,
                                   const Registration& registration, const AppearanceOptions& options,
                                   const cv::Mat& also_changed, const ParallaxPredictor& parallax) {
  AppearanceChange result;
  const std::vector<cv::DMatch>& matches = registration.matches;
  result.matches = static_cast<int>(matches.size());
  result.inliers = registration.inliers;
  if (result.inliers < options.min_inliers || registration.current_from_prior.empty()) return result;
  const cv::Mat& h = registration.current_from_prior;
  result.registered = true;
  result.homography = h;

  cv::Mat prior_f, current_f, warped, mask;
  prior.image.convertTo(prior_f, CV_32F);
  current.image.convertTo(current_f, CV_32F);
  if (options.blur_sigma_px > 0) {
    cv::GaussianBlur(prior_f, prior_f, cv::Size(), options.blur_sigma_px);
    cv::GaussianBlur(current_f, current_f, cv::Size(), options.blur_sigma_px);
  }
  const int margin = options.search_radius_px + 2;
  WarpPrior(prior_f, h, current_f.size(), margin, &warped, &mask);
  const int compared = cv::countNonZero(mask);
  result.compared_fraction = static_cast<double>(compared) / mask.total();
  if (compared == 0) return result;
  FitLighting(warped, current_f, mask, &result.gain, &result.offset);

  cv::Mat global, local;
  ComparePixels(current_f, warped, result.gain, result.offset, options, &global, &local);
  std::vector<cv::Mat> warps = {warped};                   // the prior through each plane
  for (const cv::Mat& plane : registration.more_planes) {  // where another plane registers better, it counts
    cv::Mat plane_mask, other, other_local;
    warps.emplace_back();
    WarpPrior(prior_f, plane, current_f.size(), margin, &warps.back(), &plane_mask);
    ComparePixels(current_f, warps.back(), result.gain, result.offset, options, &other, &other_local);
    cv::Mat(cv::min(global, other)).copyTo(global, plane_mask);
    cv::Mat(cv::min(local, other_local)).copyTo(local, plane_mask);
  }
  cv::Mat changed = (global > options.min_difference) & (local > options.min_structure_change) & mask;
  if (!also_changed.empty()) changed |= also_changed & mask;
  cv::morphologyEx(changed, changed, cv::MORPH_CLOSE, cv::Mat(), cv::Point(-1, -1), options.closing_px);
  cv::morphologyEx(changed, changed, cv::MORPH_OPEN, cv::Mat());
  changed &= mask;

  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(changed, labels, stats, centroids, 8, CV_32S);
  const std::vector<bool> at_edge = TouchingEdge(labels, count, mask, options.edge_margin_px);
  const int min_area = std::max(1, static_cast<int>(options.min_area_fraction * compared));
  const double min_side = options.min_side_fraction * std::min(current_f.cols, current_f.rows);
  std::vector<bool> matched_prior(prior.points.size(), false), matched_current(current.points.size(), false);
  for (const cv::DMatch& m : matches) matched_prior[m.trainIdx] = matched_current[m.queryIdx] = true;
  std::vector<cv::Point2f> prior_points, prior_in_current;
  for (const cv::Point2f& p : prior.points) prior_points.push_back(p / prior.feature_scale);
  if (!prior_points.empty()) cv::perspectiveTransform(prior_points, prior_in_current, h);
  for (int label = 1; label < count; ++label) {
    AppearanceRegion region;
    region.area_px = stats.at<int>(label, cv::CC_STAT_AREA);
    if (region.area_px < min_area) continue;
    region.current_box = cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                                  stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
    region.prior_box = PriorBox(region.current_box, h, prior.image.size());
    const auto drop = [&](DropReason reason) { result.dropped.push_back({region, reason}); };
    if (std::min(region.current_box.width, region.current_box.height) < min_side) {
      drop(DropReason::kThin);  // a seam, not a thing
      continue;
    }
    if (at_edge[label]) {
      drop(DropReason::kAtPriorEdge);  // the prior frame ends there: what it shows is cut or smeared
      continue;
    }
    const cv::Mat in_region = labels == label;
    region.score = cv::mean(local, in_region)[0];
    if (!also_changed.empty()) {
      region.marked_share = static_cast<double>(cv::countNonZero(also_changed & in_region)) / region.area_px;
    }
    const cv::Rect2f box(region.current_box);
    for (std::size_t k = 0; k < prior_in_current.size(); ++k) {
      if (!box.contains(prior_in_current[k])) continue;
      ++region.prior_features;
      region.unmatched_prior_features += !matched_prior[k];
    }
    for (std::size_t k = 0; k < current.points.size(); ++k) {
      if (!box.contains(current.points[k] / current.feature_scale)) continue;
      ++region.current_features;
      region.unmatched_current_features += !matched_current[k];
    }
    if (!KeepsUnmatchedShare(region, options)) {
      drop(DropReason::kFeaturesStillMatch);
      continue;
    }
    const std::optional<ParallaxPrediction> predicted =
        parallax ? parallax(region.current_box) : std::optional<ParallaxPrediction>();
    if (ShowsShiftedCopy(current_f, warps, region.current_box, predicted, options)) {
      drop(DropReason::kShiftedCopy);  // the same content a few pixels off: parallax, not change
      continue;
    }
    result.regions.push_back(region);
  }
  std::sort(result.regions.begin(), result.regions.end(),
            [](const AppearanceRegion& a, const AppearanceRegion& b) { return a.area_px > b.area_px; });
  return result;
}

}  // namespace patrolmap::change
