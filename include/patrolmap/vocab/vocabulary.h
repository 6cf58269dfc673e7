// A vocabulary tree over SIFT descriptors (Nistér and Stewénius; paper 002
// §III-B): hierarchical k-means with branching k and depth L, TF-IDF weights,
// stored in contiguous arrays in breadth-first order.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/status.h"
#include "patrolmap/vocab/bow.h"

namespace patrolmap::vocab {

struct VocabularyOptions {
  int branching = 10;          // k: children per node
  int depth = 4;               // L: levels below the root; up to k^L words
  int max_iterations = 25;     // cap on Lloyd iterations per k-means (never runs unbounded)
  std::uint32_t seed = 1;      // k-means++ seeding; training is deterministic for a seed
  bool IsValid(std::string* error) const;
};

class Vocabulary {
 public:
  // Called with (nodes clustered, nodes to cluster) while training.
  using Progress = std::function<void(std::size_t, std::size_t)>;

  // Trains on descriptors grouped by image (CV_32F rows of equal width; an
  // image is one document for the IDF weights). The input is never modified.
  static Status Train(const std::vector<cv::Mat>& images, const VocabularyOptions& options, Vocabulary* vocabulary,
                      const Progress& progress = {});

  // The word of each descriptor row (CV_32F), and the TF-IDF vector of them all.
  void Quantize(const cv::Mat& descriptors, std::vector<WordId>* words) const;
  void Transform(const cv::Mat& descriptors, BowVector* bow) const;

  // The ancestor at `levels_up` levels above the word's leaf (0: the leaf
  // itself); groups features for matching (the direct index).
  std::uint32_t AncestorOf(WordId word, int levels_up) const;

  int word_count() const { return static_cast<int>(idf_.size()); }
  int node_count() const { return static_cast<int>(first_child_.size()); }
  int dimension() const { return dimension_; }
  int branching() const { return branching_; }
  int depth() const { return depth_; }
  const std::vector<float>& idf() const { return idf_; }
  bool empty() const { return idf_.empty(); }

  // Versioned binary file (vocabulary_file.cc): magic, version, parameters,
  // arrays, checksum. Save writes atomically.
  Status Save(const std::string& path) const;
  static Status Load(const std::string& path, Vocabulary* vocabulary);

 private:
  friend class VocabularyBuilder;
  friend struct VocabularyFile;
  WordId WordOfDescriptor(const float* descriptor, float* scaled) const;

  int branching_ = 0;
  int depth_ = 0;
  int dimension_ = 0;
  // Per node, in breadth-first order (node 0 is the root):
  std::vector<std::uint32_t> first_child_;  // index of the first child; children are contiguous
  std::vector<std::uint16_t> child_count_;  // 0 for a leaf
  std::vector<std::int32_t> word_;          // word id of a leaf, -1 otherwise
  std::vector<std::uint32_t> parent_;       // parent node; the root is its own parent
  // node_count x dimension cluster centres in 8 bits: round(centre * scale_),
  // so SIFT (0..255) and RootSIFT (0..1) both use the full range; distances
  // are computed in float against the scaled descriptor.
  std::vector<std::uint8_t> centres_;
  float scale_ = 1.0f;
  // Per word:
  std::vector<float> idf_;                  // log(N / n_i); 0 for words no training image had
  std::vector<std::uint32_t> leaf_;         // node of each word
};

}  // namespace patrolmap::vocab
