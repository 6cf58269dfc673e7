#include "patrolmap/place/place_recognizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "patrolmap/core/option_check.h"
#include "patrolmap/vocab/descriptors.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

namespace patrolmap::place {
namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int MethodFlag(FundamentalMethod method) {
  switch (method) {
    case FundamentalMethod::kRansac: return cv::FM_RANSAC;
    case FundamentalMethod::kUsacDefault: return cv::USAC_DEFAULT;
    case FundamentalMethod::kUsacMagsac: return cv::USAC_MAGSAC;
  }
  return cv::USAC_MAGSAC;
}

// RootSIFT: L1-normalise each descriptor, then take the square root (components in [0, 1]).
void ToRootSift(cv::Mat* descriptors) {
  for (int row = 0; row < descriptors->rows; ++row) {
    float* d = descriptors->ptr<float>(row);
    double sum = 0.0;
    for (int i = 0; i < descriptors->cols; ++i) sum += std::abs(d[i]);
    if (sum <= 0.0) continue;
    for (int i = 0; i < descriptors->cols; ++i) d[i] = static_cast<float>(std::sqrt(std::abs(d[i]) / sum));
  }
}

// A ratio-test match of query feature `query` to candidate feature `candidate`, at descriptor distance `distance`.
struct Match {
  int query = -1, candidate = -1;
  float distance = 0.0f;
};

void MatchAll(const cv::Mat& query, const cv::Mat& candidate, double ratio, std::vector<Match>* matches) {
  if (query.type() == CV_8U && candidate.type() == CV_8U) {  // as a node keeps them: BFMatcher's result, faster
    std::vector<vocab::NearestTwo> nearest;
    vocab::FindNearestTwo(query, candidate, &nearest);
    for (int i = 0; i < query.rows; ++i) {
      const vocab::NearestTwo& pair = nearest[i];
      if (pair.second < 0 || pair.first_distance >= ratio * pair.second_distance) continue;
      matches->push_back({i, pair.first, pair.first_distance});
    }
    return;
  }
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_L2).knnMatch(query, candidate, knn, 2);
  for (const auto& pair : knn) {
    if (pair.size() < 2 || pair[0].distance >= ratio * pair[1].distance) continue;
    matches->push_back({pair[0].queryIdx, pair[0].trainIdx, pair[0].distance});
  }
}

// Keeps, of the matches that share a candidate feature, the one of smallest distance (the lower query index on a
// tie), in query order. The ratio test looks one way only: query features of a repeated or blank-wall pattern all
// reach the same few candidate features, and a fundamental matrix whose epipole lies there fits them all.
void KeepOneToOne(int candidate_count, std::vector<Match>* matches) {
  std::vector<int> best(candidate_count, -1);
  for (int k = 0; k < static_cast<int>(matches->size()); ++k) {
    int& kept = best[(*matches)[k].candidate];
    if (kept < 0 || (*matches)[k].distance < (*matches)[kept].distance) kept = k;
  }
  std::size_t out = 0;
  for (int k = 0; k < static_cast<int>(matches->size()); ++k) {
    if (best[(*matches)[k].candidate] == k) (*matches)[out++] = (*matches)[k];
  }
  matches->resize(out);
}

// log10 of the binomial coefficient C(n, k).
double LogChoose(int n, int k) {
  return (std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0)) / std::log(10.0);
}

// Distance of `point` to the line a x + b y + c = 0 [pixels].
double LineDistance(const cv::Vec3d& line, const cv::Point2f& point) {
  const double norm = std::hypot(line[0], line[1]);
  if (norm <= 0.0) return std::numeric_limits<double>::infinity();
  return std::abs(line[0] * point.x + line[1] * point.y + line[2]) / norm;
}

}  // namespace

FeatureExtent ExtentOf(const std::vector<cv::Point2f>& points) {
  if (points.empty()) return {};
  float min_x = points[0].x, max_x = min_x, min_y = points[0].y, max_y = min_y;
  for (const cv::Point2f& point : points) {
    min_x = std::min(min_x, point.x), max_x = std::max(max_x, point.x);
    min_y = std::min(min_y, point.y), max_y = std::max(max_y, point.y);
  }
  const double width = std::max(1.0f, max_x - min_x), height = std::max(1.0f, max_y - min_y);
  return {width * height, std::hypot(width, height)};
}

double LogNumberOfFalseAlarms(const cv::Matx33d& fundamental, const std::vector<cv::Point2f>& from,
                              const std::vector<cv::Point2f>& to, const FeatureExtent& from_extent,
                              const FeatureExtent& to_extent) {
  constexpr int kSample = 7;       // the 7-point algorithm's minimal sample
  constexpr double kModels = 3.0;  // it gives up to 3 fundamental matrices
  const int n = static_cast<int>(from.size());
  if (n <= kSample + 1 || to.size() != from.size()) return 0.0;
  std::vector<double> probability(n);
  for (int i = 0; i < n; ++i) {
    const cv::Vec3d x1(from[i].x, from[i].y, 1.0), x2(to[i].x, to[i].y, 1.0);
    const double in_to = LineDistance(fundamental * x1, to[i]) * 2.0 * to_extent.diagonal / to_extent.area;
    const double in_from = LineDistance(fundamental.t() * x2, from[i]) * 2.0 * from_extent.diagonal / from_extent.area;
    probability[i] = std::clamp(std::max(in_to, in_from), 1e-300, 1.0);
  }
  std::sort(probability.begin(), probability.end());
  const double log_tests = std::log10(kModels * (n - kSample));
  double best = std::numeric_limits<double>::infinity();
  for (int k = kSample + 1; k <= n; ++k) {
    const double log_nfa =
        log_tests + LogChoose(n, k) + LogChoose(k, kSample) + (k - kSample) * std::log10(probability[k - 1]);
    best = std::min(best, log_nfa);
  }
  return best;
}

const char* ToString(FundamentalMethod method) {
  switch (method) {
    case FundamentalMethod::kRansac: return "ransac";
    case FundamentalMethod::kUsacDefault: return "usac";
    case FundamentalMethod::kUsacMagsac: return "magsac";
  }
  return "?";
}

bool ParseFundamentalMethod(const std::string& text, FundamentalMethod* method) {
  for (FundamentalMethod candidate :
       {FundamentalMethod::kRansac, FundamentalMethod::kUsacDefault, FundamentalMethod::kUsacMagsac}) {
    if (text == ToString(candidate)) return *method = candidate, true;
  }
  return false;
}

bool PlaceOptions::IsValid(std::string* error) const {
  return OptionCheck(error)
             .InRange("place.max_features", max_features, 8, 100000)
             .Holds("place.descriptor_bits", descriptor_bits,
                    descriptor_bits == 4 || descriptor_bits == 8 || descriptor_bits == 32, "4, 8 or 32")
             .InRange("place.candidates", candidates, 1, 1000)
             .InRange("place.exclude_recent_s", exclude_recent_s, 0.0, 1e10)
             .InRange("place.exclude_recent_images", exclude_recent_images, 0, 1000000)
             .AboveAtMost("place.ratio", ratio, 0.0, 1.0)
             .InRange("place.min_matched_fraction", min_matched_fraction, 0.0, 1.0)
             .AboveAtMost("place.inlier_threshold_px", inlier_threshold_px, 0.0, 100.0)
             .InRange("place.min_inliers", min_inliers, 8, 100000)
             .InRange("place.max_log_nfa", max_log_nfa, -1000.0, 1000.0)
             .ok() &&
         query.IsValid(error);
}

PlaceRecognizer::PlaceRecognizer(const vocab::Vocabulary* vocabulary, const PlaceOptions& options)
    : vocabulary_(vocabulary), options_(options), database_(vocabulary->word_count()) {
  std::string error;
  PATROLMAP_CHECK(options.IsValid(&error));
  PATROLMAP_CHECK(vocabulary != nullptr && !vocabulary->empty() && vocabulary->dimension() == 128);
}

void DescribeFeatures(const cv::Mat& image, const PlaceOptions& options, std::vector<cv::Point2f>* points,
                      cv::Mat* descriptors) {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features);
  std::vector<cv::KeyPoint> keypoints;
  sift->detectAndCompute(image, cv::noArray(), keypoints, *descriptors);
  cv::KeyPoint::convert(keypoints, *points);
  if (descriptors->empty()) *descriptors = cv::Mat(0, 128, CV_32F);
  if (options.root_sift) ToRootSift(descriptors);
}

cv::Mat StoredDescriptors(const cv::Mat& descriptors, const PlaceOptions& options) {
  if (options.descriptor_bits == 32) return descriptors;
  cv::Mat bytes(0, vocab::kDescriptorDimension, CV_8U);  // RootSIFT (0..1) scaled by 255, SIFT (0..255) as it is
  if (descriptors.rows > 0) descriptors.convertTo(bytes, CV_8U, options.root_sift ? 255.0 : 1.0);
  return options.descriptor_bits == 4 ? vocab::PackDescriptors(bytes) : bytes;
}

Verification PlaceRecognizer::Verify(const std::vector<cv::Point2f>& query_points, const cv::Mat& query,
                                     const std::vector<cv::Point2f>& candidate_points, const cv::Mat& candidate) const {
  return VerifyPair(options_, query_points, query, candidate_points, candidate);
}

Verification VerifyPair(const PlaceOptions& options, const std::vector<cv::Point2f>& query_points,
                        const cv::Mat& query_descriptors, const std::vector<cv::Point2f>& candidate_points,
                        const cv::Mat& candidate_descriptors, std::vector<std::pair<int, int>>* inliers) {
  // Packed 4-bit rows are matched as the 8-bit values they stand for.
  const cv::Mat query = vocab::Expanded(query_descriptors), candidate = vocab::Expanded(candidate_descriptors);
  Verification verification;
  if (inliers != nullptr) inliers->clear();
  if (query.rows < 2 || candidate.rows < 2 || query.type() != candidate.type()) return verification;
  std::vector<Match> matches;
  MatchAll(query, candidate, options.ratio, &matches);
  if (options.one_to_one) KeepOneToOne(candidate.rows, &matches);
  std::vector<cv::Point2f> from, to;
  for (const Match& match : matches) {
    from.push_back(query_points[match.query]);
    to.push_back(candidate_points[match.candidate]);
  }
  verification.matches = static_cast<int>(from.size());
  verification.matched_fraction = static_cast<double>(from.size()) / std::min(query.rows, candidate.rows);
  if (verification.matched_fraction < options.min_matched_fraction || verification.matches < options.min_inliers) {
    return verification;
  }
  std::vector<unsigned char> mask;
  const cv::Mat f =
      cv::findFundamentalMat(from, to, MethodFlag(options.method), options.inlier_threshold_px, 0.999, 2000, mask);
  if (f.rows < 3 || f.cols != 3) return verification;
  verification.inliers = cv::countNonZero(mask);
  for (std::size_t k = 0; inliers != nullptr && k < mask.size(); ++k) {
    if (mask[k] != 0) inliers->emplace_back(matches[k].query, matches[k].candidate);
  }
  verification.log_nfa = LogNumberOfFalseAlarms(cv::Matx33d(f.rowRange(0, 3)), from, to, ExtentOf(query_points),
                                                ExtentOf(candidate_points));
  verification.accepted = verification.inliers >= options.min_inliers && verification.log_nfa <= options.max_log_nfa;
  return verification;
}

bool PlaceRecognizer::Allowed(const KeyFrame& query, int node) const {
  const KeyFrameNode& candidate = nodes_[node];
  if (candidate.flight != query.flight) return true;
  if (!query.timed) return query.frame_index - candidate.frame_index > options_.exclude_recent_images;
  return NsToSeconds(query.timestamp_ns - candidate.timestamp_ns) >= options_.exclude_recent_s;
}

KeyFrameNode PlaceRecognizer::StoredNode(const KeyFrameNode& described) const {
  KeyFrameNode node;
  node.flight = described.flight;
  node.timestamp_ns = described.timestamp_ns;
  node.frame_index = described.frame_index;
  node.points = described.points;
  node.descriptors = described.descriptors;  // shared
  return node;
}

int PlaceRecognizer::AddDescribedNode(const KeyFrameNode& described) {
  KeyFrameNode node = StoredNode(described);
  const int id = static_cast<int>(database_.Add(described.bow));
  nodes_.push_back(std::move(node));
  return id;
}

Status PlaceRecognizer::AddKeyFrame(const KeyFrame& key_frame, PlaceResult* result) {
  if (key_frame.image.empty() || key_frame.image.type() != CV_8UC1) {
    return Status::InvalidArgument("key frame " + std::to_string(key_frame.frame_index) + " has no grey image");
  }
  *result = PlaceResult();
  const auto start = std::chrono::steady_clock::now();
  KeyFrameNode node;
  node.flight = key_frame.flight;
  node.timestamp_ns = key_frame.timestamp_ns;
  node.frame_index = key_frame.frame_index;
  DescribeFeatures(key_frame.image, options_, &node.points, &node.descriptors);
  vocab::BowVector bow;
  std::vector<vocab::WordId> words;
  vocabulary_->Quantize(node.descriptors, &words);
  vocab::MakeBowVector(words, vocabulary_->idf().data(), &bow);
  result->features = node.descriptors.rows;
  node.descriptors = StoredDescriptors(node.descriptors, options_);
  result->seconds_features = Since(start);
  Recognise(key_frame, std::move(node), bow, result);
  return Status::Ok();
}

void PlaceRecognizer::AddDescribedKeyFrame(const KeyFrameNode& described, bool timed, PlaceResult* result) {
  *result = PlaceResult();
  KeyFrame key_frame;
  key_frame.flight = described.flight;
  key_frame.timestamp_ns = described.timestamp_ns;
  key_frame.frame_index = described.frame_index;
  key_frame.timed = timed;
  KeyFrameNode node = StoredNode(described);
  result->features = node.descriptors.rows;
  Recognise(key_frame, std::move(node), described.bow, result);
}

void PlaceRecognizer::Recognise(const KeyFrame& key_frame, KeyFrameNode node, const vocab::BowVector& bow,
                                PlaceResult* result) {
  auto start = std::chrono::steady_clock::now();
  std::vector<vocab::QueryResult> candidates;
  database_.Query(
      bow, options_.candidates, [&](vocab::EntryId entry) { return Allowed(key_frame, entry); }, &candidates,
      options_.query);
  result->seconds_query = Since(start);

  start = std::chrono::steady_clock::now();
  for (const vocab::QueryResult& candidate : candidates) {
    const KeyFrameNode& other = nodes_[candidate.entry];
    Verification verification = Verify(node.points, node.descriptors, other.points, other.descriptors);
    verification.node = static_cast<int>(candidate.entry);
    verification.bow_score = candidate.score;
    result->candidates.push_back(verification);
    if (!verification.accepted) continue;
    if (!result->match || verification.inliers > result->match->inliers) result->match = verification;
    if (!options_.accept_best) break;  // the paper stops at the first verified candidate
  }
  result->seconds_verify = Since(start);

  start = std::chrono::steady_clock::now();
  result->node = static_cast<int>(database_.Add(bow));
  result->described = node;  // the descriptors shared
  result->described.bow = bow;
  nodes_.push_back(std::move(node));
  result->seconds_add = Since(start);
}

}  // namespace patrolmap::place
