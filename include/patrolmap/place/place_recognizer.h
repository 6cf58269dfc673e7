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

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap::place {

enum class FundamentalMethod { kRansac, kUsacDefault, kUsacMagsac };
const char* ToString(FundamentalMethod method);
bool ParseFundamentalMethod(const std::string& text, FundamentalMethod* method);  // ransac, usac, magsac

struct PlaceOptions {
  int max_features = 800;            // SIFT features kept per key frame (strongest first)
  bool root_sift = true;             // RootSIFT (Arandjelovic and Zisserman) instead of plain SIFT
  int candidates = 3;                // BoW candidates verified per query (paper: n = 3)
  double exclude_recent_s = 20.0;    // nodes of the same flight this recent are not candidates [s]
  double ratio = 0.8;                // Lowe's ratio test for descriptor matches
  double min_matched_fraction = 0.1; // matches / features of the smaller frame (paper: 0.5)
  FundamentalMethod method = FundamentalMethod::kUsacMagsac;
  double inlier_threshold_px = 1.5;  // epipolar distance for a RANSAC inlier [pixels]
  int min_inliers = 50;              // a verified match needs this many inliers (chosen on experiment 3 seed 1: true >= 56, false <= 38)
  bool accept_best = false;          // verify every candidate and keep the best (paper: the first that passes)
  // Keep node descriptors in 8 bits (RootSIFT scaled by 255; SIFT is 0..255 already): a quarter
  // of the memory per node; matching distances are computed from the 8-bit values.
  bool compact_descriptors = true;
  // Reject topologically implausible candidates (the paper's future work): when the previous node
  // of the query's flight closed a loop to node m, a candidate must lie on m's flight within this
  // many nodes of m along the path. 0 turns the check off.
  int max_topological_gap = 0;
  // Direct index: match only features that share the vocabulary node this many levels above
  // their words (DBoW2's direct index), instead of every feature with every feature. 0 = brute force.
  int direct_index_levels_up = 0;

  bool IsValid(std::string* error) const;
};

// SIFT (or RootSIFT) features of a grey image, strongest max_features, as
// place recognition uses them and as vocabularies are trained on. Descriptors
// are CV_32F rows of 128 (an empty 0x128 matrix when there are none).
void DescribeFeatures(const cv::Mat& image, const PlaceOptions& options, std::vector<cv::KeyPoint>* keypoints,
                      cv::Mat* descriptors);

// A key frame to recognise.
struct KeyFrame {
  std::string flight;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  cv::Mat image;  // CV_8UC1
};

// The outcome of one verification.
struct Verification {
  int node = -1;               // the candidate node
  double bow_score = 0.0;
  int matches = 0;             // ratio-test matches
  double matched_fraction = 0.0;
  int inliers = 0;             // fundamental-matrix inliers
  bool accepted = false;
};

struct PlaceResult {
  int node = -1;                           // the node the key frame became
  int features = 0;
  std::optional<Verification> match;       // the accepted loop closure, if any
  std::vector<Verification> candidates;    // every candidate looked at
  double seconds_features = 0.0, seconds_query = 0.0, seconds_verify = 0.0, seconds_add = 0.0;
};

class PlaceRecognizer {
 public:
  // `vocabulary` must outlive the recognizer; `options` must be valid.
  PlaceRecognizer(const vocab::Vocabulary* vocabulary, const PlaceOptions& options);

  // Describes the key frame, looks for an earlier node of the same place, and
  // adds the key frame as a new node.
  Status AddKeyFrame(const KeyFrame& key_frame, PlaceResult* result);

  int node_count() const { return static_cast<int>(nodes_.size()); }

  // What the recognizer keeps of a node: enough to match later flights without the log.
  struct NodeFeatures {
    std::string flight;
    TimestampNs timestamp_ns = 0;
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    vocab::BowVector bow;
  };
  NodeFeatures Features(int node) const;

  // Adds a node described earlier (a prior map's), without querying; returns its id.
  int AddDescribedNode(NodeFeatures features);

  // Verifies two described frames (matching, fraction rule, F-RANSAC). With `groups` (the
  // direct-index node of each feature) matching stays inside equal groups.
  Verification Verify(const std::vector<cv::KeyPoint>& query_points, const cv::Mat& query,
                      const std::vector<cv::KeyPoint>& candidate_points, const cv::Mat& candidate,
                      const std::vector<std::uint32_t>* query_groups = nullptr,
                      const std::vector<std::uint32_t>* candidate_groups = nullptr) const;

 private:
  struct Node {
    std::string flight;
    TimestampNs timestamp_ns = 0;
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    std::vector<std::uint32_t> groups;  // direct-index node of each feature (when enabled)
  };
  bool Allowed(const KeyFrame& query, int node) const;
  bool Plausible(const KeyFrame& query, int node) const;

  const vocab::Vocabulary* vocabulary_;
  PlaceOptions options_;
  vocab::Database database_;
  std::vector<Node> nodes_;
  std::map<std::string, int> last_match_;  // per flight: loop closure of its latest node, -1 for none
};

}  // namespace patrolmap::place
