// Per key frame cost of place recognition, split as the paper's Table IV (features and vocabulary lookup,
// verification; the database query is in vocab_benchmark), at 376x240 and 752x480, on rendered street
// frames with the shipped vocabulary and the default options. OpenCV on one thread, as on one core of
// the onboard target.
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>

#include "patrolmap/place/place_recognizer.h"
#include "patrolmap/sim/flight.h"
#include "patrolmap/vocab/vocabulary.h"

namespace {

using namespace patrolmap;

// Two frames 0.4 s apart along the simulated street, at `width` pixels wide: a key frame and a revisit of
// its place.
const std::vector<cv::Mat>& StreetPair(int width) {
  static std::vector<cv::Mat> pairs[2];
  std::vector<cv::Mat>& cached = pairs[width > 400 ? 1 : 0];
  if (!cached.empty()) return cached;
  sim::SimulatedFlight flight = sim::MakeStreetFlight(sim::StreetOptions{});
  flight.camera = flight.camera.Scaled(width / 752.0);
  sim::Renderer renderer(&flight.scene, flight.camera);
  for (double t : {3.0, 3.4}) {
    cv::Mat image;
    renderer.Render(sim::CameraPoseAt(flight, flight.trajectory(t)), &image);
    cached.push_back(image);
  }
  return cached;
}

const vocab::Vocabulary& ShippedVocabulary() {
  static vocab::Vocabulary vocabulary;
  if (vocabulary.empty()) {
    const Status status =
        vocab::Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &vocabulary);
    if (!status.ok()) std::fprintf(stderr, "%s\n", status.message().c_str());
  }
  return vocabulary;
}

void BM_KeyFrameFeaturesAndWords(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat& image = StreetPair(static_cast<int>(state.range(0)))[0];
  const vocab::Vocabulary& vocabulary = ShippedVocabulary();
  const place::PlaceOptions options;
  std::vector<cv::Point2f> points;
  cv::Mat descriptors;
  std::vector<vocab::WordId> words;
  vocab::BowVector bow;
  for (auto _ : state) {
    place::DescribeFeatures(image, options, &points, &descriptors);
    vocabulary.Quantize(descriptors, &words);
    vocab::MakeBowVector(words, vocabulary.idf().data(), &bow);
    benchmark::DoNotOptimize(bow.words.data());
  }
  state.SetLabel(std::to_string(image.cols) + "x" + std::to_string(image.rows) + ", " +
                 std::to_string(descriptors.rows) + " features");
}
BENCHMARK(BM_KeyFrameFeaturesAndWords)->Arg(376)->Arg(752)->Unit(benchmark::kMillisecond);

void BM_KeyFrameVerification(benchmark::State& state) {
  cv::setNumThreads(1);
  const std::vector<cv::Mat>& pair = StreetPair(static_cast<int>(state.range(0)));
  place::PlaceOptions options;
  options.descriptor_bits = static_cast<int>(state.range(1));
  std::vector<cv::Point2f> query_points, candidate_points;
  cv::Mat query, candidate;
  place::DescribeFeatures(pair[0], options, &query_points, &query);
  place::DescribeFeatures(pair[1], options, &candidate_points, &candidate);
  query = place::StoredDescriptors(query, options);  // as a node keeps them
  candidate = place::StoredDescriptors(candidate, options);
  place::Verification verification;
  for (auto _ : state) {
    verification = place::VerifyPair(options, query_points, query, candidate_points, candidate);
    benchmark::DoNotOptimize(verification.inliers);
  }
  state.SetLabel(std::to_string(pair[0].cols) + "x" + std::to_string(pair[0].rows) + ", " +
                 std::to_string(verification.inliers) + " inliers, log NFA " +
                 std::to_string(static_cast<int>(verification.log_nfa)) +
                 (verification.accepted ? ", accepted" : ", rejected"));
}
BENCHMARK(BM_KeyFrameVerification)
    ->ArgNames({"width", "bits"})
    ->Args({376, 8})
    ->Args({376, 4})
    ->Args({752, 8})
    ->Args({752, 4})
    ->Unit(benchmark::kMillisecond);

// The a-contrario test alone, for 300 matches of which 250 obey the geometry.
void BM_LogNumberOfFalseAlarms(benchmark::State& state) {
  const cv::Matx33d horizontal_shift(0, 0, 0, 0, 0, -1, 0, 1, 0);
  cv::RNG rng(3);
  std::vector<cv::Point2f> from, to;
  for (int i = 0; i < 300; ++i) {
    const cv::Point2f p(static_cast<float>(rng.uniform(0.0, 376.0)), static_cast<float>(rng.uniform(0.0, 240.0)));
    from.push_back(p);
    to.push_back(i < 250 ? p + cv::Point2f(10.0f, static_cast<float>(rng.gaussian(0.5)))
                         : cv::Point2f(static_cast<float>(rng.uniform(0.0, 376.0)),
                                       static_cast<float>(rng.uniform(0.0, 240.0))));
  }
  const place::FeatureExtent extent{376.0 * 240.0, 446.0};
  for (auto _ : state) {
    benchmark::DoNotOptimize(place::LogNumberOfFalseAlarms(horizontal_shift, from, to, extent, extent));
  }
}
BENCHMARK(BM_LogNumberOfFalseAlarms)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
