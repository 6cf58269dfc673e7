#include "patrolmap/vocab/vocabulary.h"

#include "distance.h"
#include "patrolmap/core/checksum.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <random>

#include <opencv2/core.hpp>

#include "kmeans.h"

namespace patrolmap::vocab {

bool VocabularyOptions::IsValid(std::string* error) const {
  if (branching < 2 || branching > 1000) return *error = "vocab branching k must be in [2, 1000]", false;
  if (depth < 1 || depth > 10) return *error = "vocab depth L must be in [1, 10]", false;
  if (max_iterations < 1) return *error = "vocab max_iterations must be at least 1", false;
  if (std::pow(static_cast<double>(branching), depth) > 4e9)
    return *error = "vocab k^L must stay under 4e9 words", false;
  return true;
}

// Grows the tree breadth first: each queued node's points are clustered into
// children appended at the end, so children are contiguous and in BFS order.
class VocabularyBuilder {
 public:
  VocabularyBuilder(const float* data, int dimension, const VocabularyOptions& options, Vocabulary* vocabulary)
      : data_(data), dimension_(dimension), options_(options), vocabulary_(vocabulary), rng_(options.seed) {}

  void Build(std::size_t points, const Vocabulary::Progress& progress) {
    Vocabulary& v = *vocabulary_;
    v.branching_ = options_.branching;
    v.depth_ = options_.depth;
    v.dimension_ = dimension_;
    AddNode(0, nullptr);
    std::vector<std::uint32_t> all(points);
    for (std::size_t i = 0; i < points; ++i) all[i] = static_cast<std::uint32_t>(i);
    queue_.push_back({0, 0, std::move(all)});
    std::size_t done = 0;
    while (!queue_.empty()) {
      Pending pending = std::move(queue_.front());
      queue_.pop_front();
      Split(pending);
      ++done;
      if (progress) progress(done, done + queue_.size());
    }
  }

 private:
  struct Pending {
    std::uint32_t node;
    int level;
    std::vector<std::uint32_t> points;
  };

  std::uint32_t AddNode(std::uint32_t parent, const float* centre) {
    Vocabulary& v = *vocabulary_;
    const auto node = static_cast<std::uint32_t>(v.first_child_.size());
    v.first_child_.push_back(0);
    v.child_count_.push_back(0);
    v.word_.push_back(-1);
    v.parent_.push_back(parent);
    for (int d = 0; d < dimension_; ++d) {
      const float value = centre == nullptr ? 0.0f : std::round(centre[d] * v.scale_);
      v.centres_.push_back(static_cast<std::uint8_t>(std::clamp(value, 0.0f, 255.0f)));
    }
    return node;
  }

  void MakeLeaf(std::uint32_t node) {
    Vocabulary& v = *vocabulary_;
    v.word_[node] = static_cast<std::int32_t>(v.leaf_.size());
    v.leaf_.push_back(node);
  }

  void Split(Pending& pending) {
    if (pending.level == options_.depth || pending.points.size() <= 1) return MakeLeaf(pending.node);
    Clustering clustering;
    KMeans(data_, dimension_, pending.points, options_.branching, options_.max_iterations, &rng_, &clustering);
    std::vector<std::vector<std::uint32_t>> members(clustering.clusters);
    for (std::size_t i = 0; i < pending.points.size(); ++i)
      members[clustering.assignment[i]].push_back(pending.points[i]);
    pending.points = {};
    Vocabulary& v = *vocabulary_;
    v.first_child_[pending.node] = static_cast<std::uint32_t>(v.first_child_.size());
    v.child_count_[pending.node] = static_cast<std::uint16_t>(clustering.clusters);
    for (int c = 0; c < clustering.clusters; ++c) {
      const std::uint32_t child = AddNode(pending.node, &clustering.centres[static_cast<std::size_t>(c) * dimension_]);
      queue_.push_back({child, pending.level + 1, std::move(members[c])});
    }
  }

  const float* data_;
  int dimension_;
  VocabularyOptions options_;
  Vocabulary* vocabulary_;
  std::mt19937 rng_;
  std::deque<Pending> queue_;
};

namespace {

Status StackDescriptors(const std::vector<cv::Mat>& images, cv::Mat* stacked) {
  int dimension = -1;
  std::vector<cv::Mat> valid;
  for (std::size_t i = 0; i < images.size(); ++i) {
    if (images[i].empty()) continue;
    if (images[i].type() != CV_32FC1)
      return Status::InvalidArgument("descriptors of image " + std::to_string(i) + " are not CV_32F");
    if (dimension >= 0 && images[i].cols != dimension) return Status::InvalidArgument("descriptor widths differ");
    dimension = images[i].cols;
    valid.push_back(images[i]);
  }
  if (valid.empty()) return Status::InvalidArgument("no descriptors to train on");
  cv::vconcat(valid, *stacked);  // a copy: training never touches the caller's rows
  return Status::Ok();
}

}  // namespace

Status Vocabulary::Train(const std::vector<cv::Mat>& images, const VocabularyOptions& options, Vocabulary* vocabulary,
                         const Progress& progress) {
  std::string error;
  if (!options.IsValid(&error)) return Status::InvalidArgument(error);
  cv::Mat stacked;
  PATROLMAP_RETURN_IF_ERROR(StackDescriptors(images, &stacked));
  *vocabulary = Vocabulary();
  double low = 0.0, high = 0.0;
  cv::minMaxLoc(stacked, &low, &high);
  if (low < 0.0) return Status::InvalidArgument("descriptors must not be negative (SIFT or RootSIFT)");
  vocabulary->scale_ = high > 0.0 ? static_cast<float>(255.0 / high) : 1.0f;
  VocabularyBuilder(stacked.ptr<float>(), stacked.cols, options, vocabulary).Build(stacked.rows, progress);
  // IDF: log(N / n_i) over the images that hold word i.
  std::vector<std::uint32_t> holders(vocabulary->leaf_.size(), 0);
  std::vector<WordId> words;
  int documents = 0;
  for (const cv::Mat& image : images) {
    if (image.empty()) continue;
    ++documents;
    vocabulary->Quantize(image, &words);
    std::sort(words.begin(), words.end());
    words.erase(std::unique(words.begin(), words.end()), words.end());
    for (WordId word : words) ++holders[word];
  }
  vocabulary->idf_.assign(holders.size(), 0.0f);
  for (std::size_t w = 0; w < holders.size(); ++w) {
    if (holders[w] > 0) vocabulary->idf_[w] = static_cast<float>(std::log(static_cast<double>(documents) / holders[w]));
  }
  return Status::Ok();
}

WordId Vocabulary::WordOfDescriptor(const float* descriptor, float* scaled) const {
  const DistanceFunction distance = FastestDistance();  // AVX2 where the processor has it
  for (int d = 0; d < dimension_; ++d) scaled[d] = descriptor[d] * scale_;
  std::uint32_t node = 0;
  while (child_count_[node] > 0) {
    const std::uint32_t first = first_child_[node];
    std::uint32_t best = first;
    float best_distance = std::numeric_limits<float>::max();
    for (std::uint32_t child = first; child < first + child_count_[node]; ++child) {
      const float d = distance(scaled, &centres_[static_cast<std::size_t>(child) * dimension_], dimension_);
      if (d < best_distance) best_distance = d, best = child;
    }
    node = best;
  }
  return static_cast<WordId>(word_[node]);
}

void Vocabulary::Quantize(const cv::Mat& descriptors, std::vector<WordId>* words) const {
  PATROLMAP_CHECK(descriptors.empty() || (descriptors.type() == CV_32FC1 && descriptors.cols == dimension_));
  words->resize(descriptors.rows);
  std::vector<float> scaled(dimension_);
  for (int row = 0; row < descriptors.rows; ++row) {
    (*words)[row] = WordOfDescriptor(descriptors.ptr<float>(row), scaled.data());
  }
}

void Vocabulary::Transform(const cv::Mat& descriptors, BowVector* bow) const {
  std::vector<WordId> words;
  Quantize(descriptors, &words);
  MakeBowVector(words, idf_.data(), bow);
}

std::uint64_t Vocabulary::Fingerprint() const {
  const std::int32_t parameters[3] = {branching_, depth_, dimension_};
  std::uint64_t hash = Checksum(reinterpret_cast<const char*>(parameters), sizeof(parameters));
  hash = Checksum(reinterpret_cast<const char*>(&scale_), sizeof(scale_), hash);
  hash =
      Checksum(reinterpret_cast<const char*>(first_child_.data()), first_child_.size() * sizeof(std::uint32_t), hash);
  hash = Checksum(reinterpret_cast<const char*>(centres_.data()), centres_.size(), hash);
  return Checksum(reinterpret_cast<const char*>(idf_.data()), idf_.size() * sizeof(float), hash);
}

}  // namespace patrolmap::vocab
