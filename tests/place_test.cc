#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/place/place_recognizer.h"
#include "patrolmap/vocab/descriptors.h"

namespace patrolmap::place {
namespace {

const std::string kShared = std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data";
const std::string kOpencvData = "/usr/share/doc/opencv-doc/examples/data";

// A small vocabulary trained on the features of `images`.
vocab::Vocabulary VocabularyFor(const std::vector<cv::Mat>& images, const PlaceOptions& options) {
  vocab::Vocabulary vocabulary;
  std::vector<cv::Mat> descriptors;
  for (const cv::Mat& image : images) {
    std::vector<cv::Point2f> points;
    cv::Mat d;
    DescribeFeatures(image, options, &points, &d);
    descriptors.push_back(d);
  }
  vocab::VocabularyOptions vocabulary_options;
  vocabulary_options.branching = 8;
  vocabulary_options.depth = 3;
  EXPECT_TRUE(vocab::Vocabulary::Train(descriptors, vocabulary_options, &vocabulary).ok());
  return vocabulary;
}

// Two views of random 3D points with a known relative pose; descriptors are random per point (plus
// noise in the second view), and `outliers` extra points per view match nothing.
TEST(Verify, SyntheticTwoViewGeometryWithOutliers) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> pixel_noise(0.0, 0.3);
  std::normal_distribution<float> descriptor_noise(0.0f, 3.0f);
  const double f = 400.0, cx = 320.0, cy = 240.0;
  std::vector<cv::Point2f> a, b;
  cv::Mat da(0, 128, CV_32F), db(0, 128, CV_32F);
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(4.0 * u(rng), 3.0 * u(rng), 8.0 + 4.0 * u(rng));
    const Eigen::Vector3d q = Eigen::Vector3d(p.x() - 0.8, p.y() - 0.1, p.z() - 0.3);  // camera moved right
    a.emplace_back(float(f * p.x() / p.z() + cx + pixel_noise(rng)), float(f * p.y() / p.z() + cy + pixel_noise(rng)));
    b.emplace_back(float(f * q.x() / q.z() + cx + pixel_noise(rng)), float(f * q.y() / q.z() + cy + pixel_noise(rng)));
    cv::Mat row(1, 128, CV_32F);
    cv::randu(row, 0, 255);
    da.push_back(row);
    cv::Mat noisy = row.clone();
    for (int d = 0; d < 128; ++d) noisy.at<float>(d) = std::max(0.0f, noisy.at<float>(d) + descriptor_noise(rng));
    db.push_back(noisy);
  }
  for (int i = 0; i < 200; ++i) {  // clutter in the second view
    b.emplace_back(float(640 * (u(rng) + 1) / 2), float(480 * (u(rng) + 1) / 2));
    cv::Mat row(1, 128, CV_32F);
    cv::randu(row, 0, 255);
    db.push_back(row);
  }
  PlaceOptions options;
  options.root_sift = false;
  const vocab::Vocabulary vocabulary = [&] {
    vocab::Vocabulary v;
    vocab::VocabularyOptions o;
    o.branching = 4, o.depth = 2;
    EXPECT_TRUE(vocab::Vocabulary::Train({da, db}, o, &v).ok());
    return v;
  }();
  PlaceRecognizer recognizer(&vocabulary, options);
  const Verification verification = recognizer.Verify(a, da, b, db);
  EXPECT_GE(verification.matches, 290);
  EXPECT_GE(verification.inliers, 280);
  EXPECT_TRUE(verification.accepted);
  // Shuffled correspondences break the geometry: few inliers, not accepted.
  std::vector<cv::Point2f> shuffled = b;
  std::shuffle(shuffled.begin(), shuffled.begin() + 300, rng);
  const Verification broken = recognizer.Verify(a, da, shuffled, db);
  EXPECT_FALSE(broken.accepted);
  EXPECT_LT(broken.inliers, 60);
}

// The 4-bit levels hold real descriptors: on three opencv-doc photographs (800 features each), no 8-bit
// RootSIFT component lies above 84, the last level of the uniform steps, and hardly any plain SIFT component
// above 210, the largest level.
TEST(PackedDescriptors, RealComponentsFitTheLevels) {
  for (bool root_sift : {true, false}) {
    PlaceOptions options;
    options.root_sift = root_sift;
    const int top = root_sift ? vocab::kPackedLevels[12] : vocab::kPackedLevels[15];
    double above = 0.0, total = 0.0;
    for (const char* name : {"graf1.png", "aero1.jpg", "leuvenA.jpg"}) {
      const cv::Mat image = cv::imread(kOpencvData + "/" + name, cv::IMREAD_GRAYSCALE);
      if (image.empty()) GTEST_SKIP() << "opencv-doc not installed";
      std::vector<cv::Point2f> points;
      cv::Mat floats, bytes;
      DescribeFeatures(image, options, &points, &floats);
      floats.convertTo(bytes, CV_8U, root_sift ? 255.0 : 1.0);
      above += cv::countNonZero(bytes > top);
      total += static_cast<double>(bytes.total());
    }
    EXPECT_LE(above / total, root_sift ? 0.0 : 0.001) << (root_sift ? "RootSIFT" : "SIFT");
  }
}

// The 8-bit nearest-two search gives cv::BFMatcher's two nearest rows and distances, to the bit, on real
// descriptors (8-bit and expanded 4-bit), and on rows with equal distances (the lower row first, as OpenCV).
TEST(PackedDescriptors, NearestTwoIsBruteForceMatchersResult) {
  const cv::Mat one = cv::imread(kOpencvData + "/graf1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat three = cv::imread(kOpencvData + "/graf3.png", cv::IMREAD_GRAYSCALE);
  if (one.empty() || three.empty()) GTEST_SKIP() << "opencv-doc not installed";
  PlaceOptions options;
  std::vector<cv::Point2f> points;
  cv::Mat fa, fb;
  DescribeFeatures(one, options, &points, &fa);
  DescribeFeatures(three, options, &points, &fb);
  cv::Mat ties(6, 128, CV_8U, cv::Scalar(20));
  ties.row(3).setTo(cv::Scalar(21));  // rows 0-2 and 4-5 equally near to a query of 20s
  for (const int bits : {8, 4}) {
    options.descriptor_bits = bits;
    const cv::Mat a = vocab::Expanded(StoredDescriptors(fa, options)),
                  b = vocab::Expanded(StoredDescriptors(fb, options));
    for (const auto& [query, train] : {std::pair(a, b), std::pair(ties.rowRange(0, 1), ties)}) {
      std::vector<std::vector<cv::DMatch>> knn;
      cv::BFMatcher(cv::NORM_L2).knnMatch(query, train, knn, 2);
      std::vector<vocab::NearestTwo> nearest;
      vocab::FindNearestTwo(query, train, &nearest);
      ASSERT_EQ(nearest.size(), knn.size());
      for (std::size_t i = 0; i < knn.size(); ++i) {
        ASSERT_EQ(knn[i].size(), 2u);
        EXPECT_EQ(nearest[i].first, knn[i][0].trainIdx) << bits << " bits, row " << i;
        EXPECT_EQ(nearest[i].second, knn[i][1].trainIdx) << bits << " bits, row " << i;
        EXPECT_EQ(nearest[i].first_distance, knn[i][0].distance) << bits << " bits, row " << i;
        EXPECT_EQ(nearest[i].second_distance, knn[i][1].distance) << bits << " bits, row " << i;
      }
    }
  }
}

TEST(Verify, GraffitiPairFromOpencvDoc) {
  const cv::Mat one = cv::imread(kOpencvData + "/graf1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat three = cv::imread(kOpencvData + "/graf3.png", cv::IMREAD_GRAYSCALE);
  if (one.empty() || three.empty()) GTEST_SKIP() << "opencv-doc not installed";
  PlaceOptions options;
  const vocab::Vocabulary vocabulary = VocabularyFor({one, three}, options);
  PlaceRecognizer recognizer(&vocabulary, options);
  std::vector<cv::Point2f> ka, kb;
  cv::Mat da, db;
  DescribeFeatures(one, options, &ka, &da);
  DescribeFeatures(three, options, &kb, &db);
  const Verification verification = recognizer.Verify(ka, da, kb, db);
  EXPECT_TRUE(verification.accepted) << verification.matches << " matches, " << verification.inliers << " inliers";
  // The same with the 8-bit descriptors nodes keep (RootSIFT scaled by 255): about the same matches.
  cv::Mat ca, cb;
  da.convertTo(ca, CV_8U, 255.0);
  db.convertTo(cb, CV_8U, 255.0);
  const Verification compact = recognizer.Verify(ka, ca, kb, cb);
  EXPECT_TRUE(compact.accepted);
  EXPECT_NEAR(compact.matches, verification.matches, 0.05 * verification.matches);
  EXPECT_EQ(recognizer.Verify(ka, da, kb, cb).matches, 0);  // float against 8-bit is refused, not mixed
  // Packed 4-bit, as nodes keep them by default: still accepted, with at most 15 % fewer matches.
  const cv::Mat pa = vocab::PackDescriptors(ca), pb = vocab::PackDescriptors(cb);
  ASSERT_EQ(pa.cols, 64);
  const Verification packed = recognizer.Verify(ka, pa, kb, pb);
  EXPECT_TRUE(packed.accepted) << packed.matches << " matches, " << packed.inliers << " inliers";
  EXPECT_GE(packed.matches, 0.85 * compact.matches);
  EXPECT_LE(packed.matches, 1.05 * compact.matches);
  // A map of format 7 keeps 8-bit descriptors; a new patrol's 4-bit ones match them on the same scale.
  const Verification mixed = recognizer.Verify(ka, ca, kb, pb);
  EXPECT_TRUE(mixed.accepted);
  EXPECT_GE(mixed.matches, 0.85 * compact.matches);
  // Plain SIFT (8-bit already) packed: its larger components fall on the coarse top levels.
  options.root_sift = false;
  std::vector<cv::Point2f> sa, sb;
  cv::Mat fa, fb, ba, bb;
  DescribeFeatures(one, options, &sa, &fa);
  DescribeFeatures(three, options, &sb, &fb);
  fa.convertTo(ba, CV_8U);
  fb.convertTo(bb, CV_8U);
  const Verification sift = VerifyPair(options, sa, ba, sb, bb);
  const Verification sift_packed = VerifyPair(options, sa, vocab::PackDescriptors(ba), sb, vocab::PackDescriptors(bb));
  EXPECT_TRUE(sift.accepted);
  EXPECT_TRUE(sift_packed.accepted) << sift_packed.matches << " matches, " << sift_packed.inliers << " inliers";
  EXPECT_GE(sift_packed.matches, 0.85 * sift.matches);
  std::printf("graf 1/3 matches: RootSIFT float %d, 8-bit %d, 4-bit %d; SIFT 8-bit %d, 4-bit %d\n",
              verification.matches, compact.matches, packed.matches, sift.matches, sift_packed.matches);
}

// Shared real revisits: EuRoC left_img_0/1 and 2/3, DBoW2 image1/image3 are the same place; image0/image2 not.
TEST(PlaceRecognizer, RealRevisitsAreFoundAndOthersNot) {
  if (!std::filesystem::exists(kShared + "/dbow2_demo/image0.png")) GTEST_SKIP() << "shared data not present";
  std::vector<cv::Mat> images;
  for (int i = 0; i < 4; ++i) images.push_back(cv::imread(kShared + cv::format("/dbow2_demo/image%d.png", i), 0));
  for (int i = 0; i < 4; ++i)
    images.push_back(cv::imread(kShared + cv::format("/euroc_revisit_pairs/left_img_%d.png", i), 0));
  PlaceOptions options;
  options.exclude_recent_s = 0.0;
  const vocab::Vocabulary vocabulary = VocabularyFor(images, options);
  PlaceRecognizer recognizer(&vocabulary, options);
  const std::vector<int> expected_match = {-1, -1, -1, 1, -1, 4, -1, 6};  // per image: the earlier node it revisits
  for (std::size_t i = 0; i < images.size(); ++i) {
    PlaceResult result;
    ASSERT_TRUE(
        recognizer
            .AddKeyFrame({i < 4 ? "dbow2" : "euroc", SecondsToNs(i), static_cast<std::int64_t>(i), images[i]}, &result)
            .ok());
    EXPECT_EQ(result.node, static_cast<int>(i));
    EXPECT_EQ(result.match ? result.match->node : -1, expected_match[i]) << "image " << i;
  }
}

TEST(PlaceRecognizer, RecentNodesOfTheSameFlightAreNotCandidates) {
  const cv::Mat one = cv::imread(kOpencvData + "/graf1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat three = cv::imread(kOpencvData + "/graf3.png", cv::IMREAD_GRAYSCALE);
  if (one.empty() || three.empty()) GTEST_SKIP() << "opencv-doc not installed";
  PlaceOptions options;
  options.exclude_recent_s = 20.0;
  const vocab::Vocabulary vocabulary = VocabularyFor({one, three}, options);
  PlaceRecognizer recognizer(&vocabulary, options);
  PlaceResult result;
  ASSERT_TRUE(recognizer.AddKeyFrame({"a", SecondsToNs(0), 0, one}, &result).ok());
  ASSERT_TRUE(recognizer.AddKeyFrame({"a", SecondsToNs(5), 1, three}, &result).ok());
  EXPECT_FALSE(result.match.has_value());  // 5 s later in the same flight: a neighbour, not a candidate
  EXPECT_TRUE(result.candidates.empty());
  ASSERT_TRUE(recognizer.AddKeyFrame({"a", SecondsToNs(30), 2, three}, &result).ok());
  ASSERT_TRUE(result.match.has_value());  // 30 s later both earlier nodes are candidates and verify
  EXPECT_LE(result.match->node, 1);
  EXPECT_EQ(result.candidates.size(), 1u);  // the first verified candidate ends the search (paper)
  EXPECT_EQ(recognizer.node_count(), 3);
  EXPECT_FALSE(recognizer.AddKeyFrame({"b", 0, 4, cv::Mat()}, &result).ok());
}

// A log without timestamps counts "recent" in images (place.exclude_recent_images): with 2, the image
// 2 after a node does not see it as a candidate; 3 after does.
TEST(PlaceRecognizer, WithoutTimesRecentIsCountedInImages) {
  const cv::Mat one = cv::imread(kOpencvData + "/graf1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat three = cv::imread(kOpencvData + "/graf3.png", cv::IMREAD_GRAYSCALE);
  if (one.empty() || three.empty()) GTEST_SKIP() << "opencv-doc not installed";
  PlaceOptions options;
  options.exclude_recent_images = 2;  // a node is a candidate from 3 images after it
  const vocab::Vocabulary vocabulary = VocabularyFor({one, three}, options);
  PlaceRecognizer recognizer(&vocabulary, options);
  PlaceResult result;
  const auto add = [&](std::int64_t index, const cv::Mat& image) {
    KeyFrame key_frame{"a", 0, index, image};
    key_frame.timed = false;  // the same time everywhere: only the image index can tell recent nodes
    ASSERT_TRUE(recognizer.AddKeyFrame(key_frame, &result).ok());
  };
  add(10, three);
  add(12, three);  // the same image 2 images later: recent, not a candidate
  EXPECT_TRUE(result.candidates.empty());
  EXPECT_FALSE(result.match.has_value());
  add(13, three);  // node 0 is 3 images back: a candidate, and it verifies; node 1 (1 back) is not
  ASSERT_TRUE(result.match.has_value());
  EXPECT_EQ(result.match->node, 0);
  EXPECT_EQ(result.candidates.size(), 1u);
  (void)one;
}

}  // namespace
}  // namespace patrolmap::place

namespace patrolmap::place {
namespace {}  // namespace
}  // namespace patrolmap::place

namespace patrolmap::place {
namespace {

// Correspondences of a known two-view geometry: points on a fronto-parallel plane shifted sideways, so
// x2 = x1 + (d, 0) and F fixes only the rows (y2 = y1).
void ShiftedPoints(int count, double shift, cv::RNG* rng, std::vector<cv::Point2f>* from,
                   std::vector<cv::Point2f>* to) {
  for (int i = 0; i < count; ++i) {
    const cv::Point2f p(static_cast<float>(rng->uniform(10.0, 630.0)), static_cast<float>(rng->uniform(10.0, 470.0)));
    from->push_back(p);
    to->push_back(p + cv::Point2f(static_cast<float>(shift), 0.0f));
  }
}

// The a-contrario test (ORSA): a geometry many matches obey exactly is meaningful (log NFA far below 0),
// random matches are not (above 0), and the same geometry with its error scaled with the image keeps its
// verdict at any resolution.
TEST(LogNumberOfFalseAlarms, ExactGeometryIsMeaningfulAndRandomMatchesAreNot) {
  const cv::Matx33d horizontal_shift(0, 0, 0, 0, 0, -1, 0, 1, 0);  // x2^T F x1 = y1 - y2
  const FeatureExtent vga{640.0 * 480.0, 800.0};
  cv::RNG rng(7);
  std::vector<cv::Point2f> from, to;
  ShiftedPoints(60, 25.0, &rng, &from, &to);
  for (cv::Point2f& p : to) p.y += static_cast<float>(rng.gaussian(0.3));  // sub-pixel noise
  const double exact = LogNumberOfFalseAlarms(horizontal_shift, from, to, vga, vga);
  EXPECT_LT(exact, -100.0);
  std::vector<cv::Point2f> random_to;
  for (std::size_t i = 0; i < from.size(); ++i) {
    random_to.emplace_back(static_cast<float>(rng.uniform(0.0, 640.0)), static_cast<float>(rng.uniform(0.0, 480.0)));
  }
  EXPECT_GT(LogNumberOfFalseAlarms(horizontal_shift, from, random_to, vga, vga), 0.0);
  // Twice the resolution, twice the error in pixels: the same probability per match, the same NFA.
  std::vector<cv::Point2f> big_from, big_to;
  for (std::size_t i = 0; i < from.size(); ++i) big_from.push_back(from[i] * 2.0f), big_to.push_back(to[i] * 2.0f);
  const FeatureExtent big{4.0 * vga.area, 2.0 * vga.diagonal};
  EXPECT_NEAR(LogNumberOfFalseAlarms(horizontal_shift, big_from, big_to, big, big), exact, 1e-6);
  // Too few matches to say anything: 0.
  EXPECT_EQ(LogNumberOfFalseAlarms(horizontal_shift, {from.begin(), from.begin() + 8}, {to.begin(), to.begin() + 8},
                                   vga, vga),
            0.0);
}

// The NFA by hand for a geometry whose error shows 10 times larger in the second image (it is stretched 10
// times vertically): p_i = 2 d_i D / A with d_i the larger distance, the second image's, and
// log NFA = min over k of log10(3 (n - 7) C(n, k) C(k, 7) p_(k)^(k - 7)). Either image's probability alone,
// or one without the diagonal, would give another number.
TEST(LogNumberOfFalseAlarms, EqualsTheFormulaWithTheLargerOfTheTwoImagesErrors) {
  const cv::Matx33d stretch(0, 0, 0, 0, 0, -1, 0, 10, 0);  // x2^T F x1 = 10 y1 - y2
  const FeatureExtent image{640.0 * 480.0, 800.0};
  constexpr int n = 12;
  std::vector<cv::Point2f> from, to;
  std::vector<double> p;
  for (int i = 0; i < n; ++i) {
    const float error = 0.5f * static_cast<float>(i + 1);  // in the second image: 10 times the first's
    from.emplace_back(50.0f * i, 4.0f * i);
    to.emplace_back(50.0f * i, 40.0f * i + error);
    p.push_back(2.0 * error * image.diagonal / image.area);
  }
  const auto log_choose = [](int a, int b) {
    return (std::lgamma(a + 1.0) - std::lgamma(b + 1.0) - std::lgamma(a - b + 1.0)) / std::log(10.0);
  };
  double expected = std::numeric_limits<double>::infinity();
  for (int k = 8; k <= n; ++k) {
    expected = std::min(
        expected, std::log10(3.0 * (n - 7)) + log_choose(n, k) + log_choose(k, 7) + (k - 7) * std::log10(p[k - 1]));
  }
  EXPECT_NEAR(LogNumberOfFalseAlarms(stretch, from, to, image, image), expected, 1e-6);
  // Swapping the images (F transposed) measures the same errors.
  EXPECT_NEAR(LogNumberOfFalseAlarms(stretch.t(), to, from, image, image), expected, 1e-6);
}

TEST(PlaceOptions, OutOfRangeValuesNameKeyValueAndRule) {
  PlaceOptions options;
  std::string error;
  options.max_log_nfa = std::nan("");
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error, "place.max_log_nfa = nan: must be a number in [-1000, 1000]");
  options = PlaceOptions();
  options.min_inliers = 7;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error, "place.min_inliers = 7: must be an integer in [8, 100000]");
}

}  // namespace
}  // namespace patrolmap::place

namespace patrolmap::place {
namespace {

// Lowe's ratio test (ratio 0.8): a match is kept when its nearest candidate is clearly nearer than the
// second nearest. 10 query descriptors have one candidate at 0.1 (the next is some 4 away): kept. 10 have
// two candidates at 0.50 and 0.52 (ratio 0.96): dropped.
TEST(VerifyPair, RatioTestKeepsOnlyUnambiguousMatches) {
  cv::RNG rng(11);
  cv::Mat query(20, 128, CV_32F), candidate(30, 128, CV_32F);
  rng.fill(query, cv::RNG::UNIFORM, 0.0, 1.0);
  std::vector<cv::Point2f> query_points, candidate_points;
  const auto offset = [&rng](double length) {
    cv::Mat direction(1, 128, CV_32F);
    rng.fill(direction, cv::RNG::NORMAL, 0.0, 1.0);
    return cv::Mat(direction * (length / cv::norm(direction)));
  };
  for (int i = 0; i < 20; ++i) query_points.emplace_back(10.0f * i, 5.0f);
  for (int i = 0; i < 10; ++i) candidate.row(i) = query.row(i) + offset(0.1);
  for (int i = 10; i < 20; ++i) {
    candidate.row(i) = query.row(i) + offset(0.50);
    candidate.row(i + 10) = query.row(i) + offset(0.52);
  }
  for (int j = 0; j < 30; ++j) candidate_points.emplace_back(7.0f * j, 9.0f);
  const Verification v = VerifyPair(PlaceOptions(), query_points, query, candidate_points, candidate);
  EXPECT_EQ(v.matches, 10);
  EXPECT_DOUBLE_EQ(v.matched_fraction, 10.0 / 20.0);
}

// Query features of one repeated pattern all pass the ratio test to the same few candidate features; kept one to
// one, each candidate feature keeps its closest query feature only.
TEST(VerifyPair, OneToOneKeepsTheClosestMatchOfEachCandidateFeature) {
  cv::RNG rng(12);
  cv::Mat candidate(40, 128, CV_32F), query(24, 128, CV_32F);
  rng.fill(candidate, cv::RNG::UNIFORM, 0.0, 1.0);
  std::vector<cv::Point2f> query_points, candidate_points;
  for (int j = 0; j < 40; ++j) candidate_points.emplace_back(5.0f * j, 3.0f * (j % 7));
  for (int i = 0; i < 24; ++i) {
    // Query features 0-19 are copies of candidate features 0-3, five each, 0.01 * i apart; 20-23 match 10-13.
    cv::Mat noise(1, 128, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    const int source = i < 20 ? i % 4 : 10 + i - 20;
    query.row(i) = candidate.row(source) + noise * (0.01 * (i + 1) / cv::norm(noise));
    query_points.emplace_back(4.0f * i, 2.0f * (i % 5));
  }
  PlaceOptions options;
  options.one_to_one = false;
  EXPECT_EQ(VerifyPair(options, query_points, query, candidate_points, candidate).matches, 24);
  options.one_to_one = true;
  const Verification v = VerifyPair(options, query_points, query, candidate_points, candidate);
  EXPECT_EQ(v.matches, 8);  // candidate features 0-3 (from query 0-3, the closest copies) and 10-13
}

}  // namespace
}  // namespace patrolmap::place
