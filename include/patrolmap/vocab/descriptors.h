// How a node's descriptors are kept for matching later flights (DESIGN.md, map format): float rows of 128
// (CV_32F), one byte per component (CV_8U, 128 columns), or two components per byte (CV_8U, 64 columns:
// component 2k in the high nibble, 2k + 1 in the low one). Every matcher reads them through Expanded, so the
// three kinds are compared on one scale.
#pragma once

#include <opencv2/core/mat.hpp>

namespace patrolmap::vocab {

constexpr int kDescriptorDimension = 128;                 // SIFT
constexpr int kPackedColumns = kDescriptorDimension / 2;  // two 4-bit components a byte
// The sixteen 8-bit values the 4-bit levels stand for. Up to 84 in steps of 7: stored 8-bit RootSIFT components
// stayed at or below 84 of 255 on seven real pairs (EuRoC, graf, leuven, KITTI; BENCHMARKS.md), so RootSIFT
// uses uniform steps only. Plain SIFT components reach about 220 (7 % of them above 105 on three opencv-doc
// photographs, place_test), which the three coarse top levels cover. Values between levels go to the nearer.
constexpr int kPackedLevels[16] = {0, 7, 14, 21, 28, 35, 42, 49, 56, 63, 70, 77, 84, 110, 150, 210};

// Whether `descriptors` are two 4-bit components a byte.
bool IsPacked(const cv::Mat& descriptors);

// 8-bit descriptors (CV_8U rows of 128) as 4-bit levels, two a byte (CV_8U rows of 64): each component
// as the nearest of kPackedLevels. An empty matrix stays empty (0x64).
cv::Mat PackDescriptors(const cv::Mat& bytes);

// Packed descriptors back as 8-bit rows of 128 (each level's value); any other kind as it is (no copy).
cv::Mat Expanded(const cv::Mat& descriptors);

// Whether a stored descriptor matrix has one of the three kinds above (for readers of map files).
bool IsStoredDescriptorKind(const cv::Mat& descriptors);

// The two rows of `train` nearest to a row of `query` by Euclidean distance, the nearer first (on equal
// distances the lower row); -1 and infinity where `train` has fewer rows.
struct NearestTwo {
  int first = -1, second = -1;
  float first_distance = 0.0f, second_distance = 0.0f;
};

// NearestTwo of every row of `query` among the rows of `train`, both 8-bit rows of 128. The squared distances
// are summed exactly in integers (AVX2 where the processor has it), then square-rooted in float: the distances
// and the order of cv::BFMatcher(cv::NORM_L2).knnMatch(query, train, k = 2), whose 8-bit loop OpenCV 4.6 runs
// one component at a time.
void FindNearestTwo(const cv::Mat& query, const cv::Mat& train, std::vector<NearestTwo>* nearest);

}  // namespace patrolmap::vocab
