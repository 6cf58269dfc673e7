// Place recognition for key frames (paper 002 §III-B): SIFT features, a
// bag-of-words query for the top candidates, descriptor matching with the
// paper's matched-fraction rule, and fundamental-matrix verification
// (x2^T F x1 = 0, the improvement the paper proposes). Every key frame
// becomes a node of the database, verified or not.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/core/key_frame_node.h"
#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap::place {

enum class FundamentalMethod { kRansac, kUsacDefault, kUsacMagsac };
const char* ToString(FundamentalMethod method);
bool ParseFundamentalMethod(const std::string& text, FundamentalMethod* method);  // ransac, usac, magsac

struct PlaceOptions {
  int max_features = 800;          // SIFT features kept per key frame (strongest first)
  bool root_sift = true;           // RootSIFT (Arandjelovic and Zisserman) instead of plain SIFT
  int candidates = 3;              // BoW candidates verified per query (paper: n = 3)
  double exclude_recent_s = 20.0;  // nodes of the same flight this recent are not candidates [s]
  // For logs without timestamps (image collections): nodes of the same flight at most this many images
  // before the query are not candidates (1: the image just before; 0: none excluded).
  int exclude_recent_images = 1;
  double ratio = 0.8;  // Lowe's ratio test for descriptor matches
  // Each candidate feature keeps only its closest query match (as COLMAP's cross check): many query features of a
  // repeated pattern matched to a few candidate features fit a fundamental matrix by chance. Off by default: at
  // max_log_nfa -20 it refuses no real pair more and loses one real revisit of seven (BENCHMARKS.md, "Verification
  // on real revisits"); with a looser rule it keeps every real pair of different scenes out.
  bool one_to_one = false;
  double min_matched_fraction = 0.1;  // matches / features of the smaller frame (paper: 0.5)
  FundamentalMethod method = FundamentalMethod::kUsacMagsac;
  double inlier_threshold_px = 1.5;  // epipolar distance for a RANSAC inlier [pixels]
  // A verified match needs at least min_inliers inliers and an a-contrario number of false alarms
  // (LogNumberOfFalseAlarms: how many such fundamental matrices chance alone would give) of at most
  // 10^max_log_nfa. The NFA scales with the image and the match count, so one setting holds from
  // 376x240 key frames to megapixel photographs.
  int min_inliers = 15;
  // 10^-20 false alarms: the a-contrario rule (Moisan and Stival) with a margin below the most meaningful false
  // matches measured, real (10^-8.2: office chairs in a ScanNet room and the TUM office) and simulated (10^-15.4:
  // repeated facades 26 m apart); BENCHMARKS.md, "Verification on real revisits".
  double max_log_nfa = -20.0;
  bool accept_best = false;  // verify every candidate and keep the best (paper: the first that passes)
  // Bits a node keeps of each descriptor component, matched as such: 32 (floats), 8 (RootSIFT scaled by 255; SIFT is
  // 0..255 already) or 4 (two components a byte at steps of 7, vocab/descriptors.h: 64 instead of 512 bytes a
  // feature). Query and stored descriptors are quantised alike.
  int descriptor_bits = 4;
  // How much of the inverted index a query reads (vocab::QueryOptions): exhaustive, or two-stage (the lists
  // of the query's rarest words, then the best entries scored exactly).
  vocab::QueryOptions query;

  bool IsValid(std::string* error) const;
};

// SIFT (or RootSIFT) features of a grey image, strongest max_features, as
// place recognition uses them and as vocabularies are trained on. Descriptors
// are CV_32F rows of 128 (an empty 0x128 matrix when there are none).
void DescribeFeatures(const cv::Mat& image, const PlaceOptions& options, std::vector<cv::Point2f>* points,
                      cv::Mat* descriptors);

// The descriptors a node keeps of DescribeFeatures' float rows: as they are, 8-bit, or packed 4-bit
// (`descriptor_bits`; vocab/descriptors.h).
cv::Mat StoredDescriptors(const cv::Mat& descriptors, const PlaceOptions& options);

// A key frame to recognise.
struct KeyFrame {
  std::string flight;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  cv::Mat image;      // CV_8UC1
  bool timed = true;  // false: the log has no timestamps, "recent" is counted in images
};

// The outcome of one verification.
struct Verification {
  int node = -1;  // the candidate node
  double bow_score = 0.0;
  int matches = 0;  // ratio-test matches
  double matched_fraction = 0.0;
  int inliers = 0;       // fundamental-matrix inliers
  double log_nfa = 0.0;  // log10 of the number of false alarms of the fundamental matrix (0 when none fitted)
  bool accepted = false;
};

// Size of the image a frame's features were found in, as verification measures it: the bounding box of
// the feature positions (a map file keeps positions, not image sizes).
struct FeatureExtent {
  double area = 1.0;      // [pixels^2]
  double diagonal = 1.0;  // [pixels]
};
FeatureExtent ExtentOf(const std::vector<cv::Point2f>& points);

// The a-contrario test of ORSA / AC-RANSAC (Moisan and Stival 2004; Moisan, Moulon and Monasse 2012) for a
// fundamental matrix F with x2^T F x1 = 0 over n matches: with the matches sorted by the probability
// p_i = 2 d_i D / A that a random point lies as close to its epipolar line (d_i the larger of the two
// images' distances, D and A the image's diagonal and area), returns
//   min over k > 7 of log10( 3 (n - 7) C(n, k) C(k, 7) p_(k)^(k - 7) ),
// the expected number of models as good as F among random matches. Below 0 the match is meaningful.
double LogNumberOfFalseAlarms(const cv::Matx33d& fundamental, const std::vector<cv::Point2f>& from,
                              const std::vector<cv::Point2f>& to, const FeatureExtent& from_extent,
                              const FeatureExtent& to_extent);

struct PlaceResult {
  int node = -1;  // the node the key frame became
  // ... as the map keeps it: flight, time, frame, features (descriptors shared with the recognizer) and BoW vector;
  // the caller adds what the recognizer does not know (thumbnail, GPS, heading).
  KeyFrameNode described;
  int features = 0;
  std::optional<Verification> match;     // the accepted loop closure, if any
  std::vector<Verification> candidates;  // every candidate looked at
  double seconds_features = 0.0, seconds_query = 0.0, seconds_verify = 0.0, seconds_add = 0.0;
};

// Verifies two described frames: ratio-test matching of every feature with every feature,
// the matched-fraction rule, a fundamental matrix by `options.method`, and the inlier and a-contrario rules.
// With `inliers`, the fundamental matrix's inlier matches as (query feature, candidate feature) pairs.
Verification VerifyPair(const PlaceOptions& options, const std::vector<cv::Point2f>& query_points, const cv::Mat& query,
                        const std::vector<cv::Point2f>& candidate_points, const cv::Mat& candidate,
                        std::vector<std::pair<int, int>>* inliers = nullptr);

class PlaceRecognizer {
 public:
  // `vocabulary` must outlive the recognizer; `options` must be valid.
  PlaceRecognizer(const vocab::Vocabulary* vocabulary, const PlaceOptions& options);

  // Describes the key frame, looks for an earlier node of the same place, and
  // adds the key frame as a new node.
  Status AddKeyFrame(const KeyFrame& key_frame, PlaceResult* result);

  int node_count() const { return static_cast<int>(nodes_.size()); }

  // Adds a node described earlier (a prior map's), without querying; returns its id. Keeps its flight, time,
  // frame, features and BoW vector (the descriptors shared, not copied).
  int AddDescribedNode(const KeyFrameNode& node);

  // Recognises a node described earlier (a map's, when maps are merged) as AddKeyFrame recognises a key
  // frame, from its stored features and BoW vector, then adds it. `timed`: its log had timestamps. With the
  // stored features of a key frame, the result is AddKeyFrame's.
  void AddDescribedKeyFrame(const KeyFrameNode& node, bool timed, PlaceResult* result);

  // Verifies two described frames (matching, fraction rule, F-RANSAC).
  Verification Verify(const std::vector<cv::Point2f>& query_points, const cv::Mat& query,
                      const std::vector<cv::Point2f>& candidate_points, const cv::Mat& candidate) const;

 private:
  // What the recognizer keeps of a described node: its flight, time, frame and features (its BoW vector is the
  // database's; the descriptors shared).
  KeyFrameNode StoredNode(const KeyFrameNode& described) const;
  bool Allowed(const KeyFrame& query, int node) const;
  // Queries the database for `node`'s place, verifies the candidates, and adds it.
  void Recognise(const KeyFrame& key_frame, KeyFrameNode node, const vocab::BowVector& bow, PlaceResult* result);

  const vocab::Vocabulary* vocabulary_;
  PlaceOptions options_;
  vocab::Database database_;
  std::vector<KeyFrameNode> nodes_;
};

}  // namespace patrolmap::place
