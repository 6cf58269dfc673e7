#include "patrolmap/vocab/descriptors.h"

#include <algorithm>
#include <cstdlib>
#include <iterator>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace patrolmap::vocab {
namespace {

// Packing keeps the nearest of the sixteen levels of each component; expanding gives those levels' values
// back in 8-bit rows of 128, component by component.
TEST(PackedDescriptors, RoundTripIsTheNearestLevel) {
  cv::Mat bytes(2, kDescriptorDimension, CV_8U);
  for (int row = 0; row < bytes.rows; ++row) {
    for (int k = 0; k < kDescriptorDimension; ++k)
      bytes.at<std::uint8_t>(row, k) = static_cast<std::uint8_t>(k + 127 * row);
  }
  const cv::Mat packed = PackDescriptors(bytes);
  ASSERT_TRUE(IsPacked(packed));
  EXPECT_EQ(packed.rows, 2);
  EXPECT_EQ(packed.cols, 64);
  const cv::Mat expanded = Expanded(packed);
  ASSERT_EQ(expanded.type(), CV_8U);
  ASSERT_EQ(expanded.cols, kDescriptorDimension);
  for (int row = 0; row < bytes.rows; ++row) {
    for (int k = 0; k < kDescriptorDimension; ++k) {
      const int value = bytes.at<std::uint8_t>(row, k), kept = expanded.at<std::uint8_t>(row, k);
      ASSERT_NE(std::find(std::begin(kPackedLevels), std::end(kPackedLevels), kept), std::end(kPackedLevels));
      for (int level : kPackedLevels) ASSERT_LE(std::abs(kept - value), std::abs(level - value)) << value;
    }
  }
  EXPECT_EQ(expanded.at<std::uint8_t>(0, 10), 7);     // 10 -> 7
  EXPECT_EQ(expanded.at<std::uint8_t>(0, 11), 14);    // 11 -> 14, the nearer
  EXPECT_EQ(expanded.at<std::uint8_t>(0, 84), 84);    // RootSIFT's largest: exact
  EXPECT_EQ(expanded.at<std::uint8_t>(1, 127), 210);  // 254 -> 210, the largest level
}

TEST(PackedDescriptors, OtherKindsPassThroughAndEmptyStaysEmpty) {
  const cv::Mat floats(4, kDescriptorDimension, CV_32F, cv::Scalar(0.5));
  EXPECT_FALSE(IsPacked(floats));
  EXPECT_EQ(Expanded(floats).data, floats.data);  // no copy
  const cv::Mat bytes(4, kDescriptorDimension, CV_8U, cv::Scalar(9));
  EXPECT_EQ(Expanded(bytes).data, bytes.data);
  const cv::Mat empty = PackDescriptors(cv::Mat(0, kDescriptorDimension, CV_8U));
  EXPECT_EQ(empty.rows, 0);
  EXPECT_TRUE(Expanded(empty).empty());
}

TEST(PackedDescriptors, StoredKinds) {
  EXPECT_TRUE(IsStoredDescriptorKind(cv::Mat()));
  EXPECT_TRUE(IsStoredDescriptorKind(cv::Mat(2, 128, CV_32F)));
  EXPECT_TRUE(IsStoredDescriptorKind(cv::Mat(2, 128, CV_8U)));
  EXPECT_TRUE(IsStoredDescriptorKind(cv::Mat(2, 64, CV_8U)));
  EXPECT_FALSE(IsStoredDescriptorKind(cv::Mat(2, 64, CV_32F)));
  EXPECT_FALSE(IsStoredDescriptorKind(cv::Mat(2, 100, CV_8U)));
  EXPECT_FALSE(IsStoredDescriptorKind(cv::Mat(2, 128, CV_16U)));
}

}  // namespace
}  // namespace patrolmap::vocab
