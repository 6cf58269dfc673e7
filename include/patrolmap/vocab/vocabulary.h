// A vocabulary tree over SIFT descriptors (Nistér and Stewénius; paper 002
// §III-B): hierarchical k-means with branching k and depth L, TF-IDF weights,
// stored in contiguous arrays in breadth-first order.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/status.h"
#include "patrolmap/vocab/bow.h"

namespace patrolmap::vocab {

// An allocator whose resize() leaves new elements uninitialised, so loading a
// large vocabulary writes each byte once (the file read) instead of twice.
template <typename T>
struct UninitialisedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <typename U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* pointer) noexcept {
    ::new (static_cast<void*>(pointer)) U;
  }
  template <typename U, typename... Args>
  void construct(U* pointer, Args&&... args) {
    ::new (static_cast<void*>(pointer)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using Array = std::vector<T, UninitialisedAllocator<T>>;

struct VocabularyOptions {
  int branching = 10;       // k: children per node
  int depth = 4;            // L: levels below the root; up to k^L words
  int max_iterations = 25;  // cap on Lloyd iterations per k-means (never runs unbounded)
  std::uint32_t seed = 1;   // k-means++ seeding; training is deterministic for a seed
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

  int word_count() const { return static_cast<int>(idf_.size()); }
  int node_count() const { return static_cast<int>(first_child_.size()); }
  int dimension() const { return dimension_; }
  int branching() const { return branching_; }
  int depth() const { return depth_; }
  const Array<float>& idf() const { return idf_; }
  // A checksum of the tree and its weights: two vocabularies quantise alike exactly when they have the
  // same fingerprint. A map file records it, so a later flight is matched with the same vocabulary.
  std::uint64_t Fingerprint() const;
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
  Array<std::uint32_t> first_child_;  // index of the first child; children are contiguous
  Array<std::uint16_t> child_count_;  // 0 for a leaf
  Array<std::int32_t> word_;          // word id of a leaf, -1 otherwise
  Array<std::uint32_t> parent_;       // parent node; the root is its own parent
  // node_count x dimension cluster centres in 8 bits: round(centre * scale_),
  // so SIFT (0..255) and RootSIFT (0..1) both use the full range; distances
  // are computed in float against the scaled descriptor.
  Array<std::uint8_t> centres_;
  float scale_ = 1.0f;
  // Per word:
  Array<float> idf_;           // log(N / n_i); 0 for words no training image had
  Array<std::uint32_t> leaf_;  // node of each word
};

}  // namespace patrolmap::vocab
