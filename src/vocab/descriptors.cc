#include "patrolmap/vocab/descriptors.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>

#include "distance.h"
#include "patrolmap/core/status.h"

namespace patrolmap::vocab {
namespace {

// The nearest level of every 8-bit value (ties to the lower).
struct LevelTable {
  LevelTable() {
    for (int value = 0; value < 256; ++value) {
      int best = 0;
      for (int level = 1; level < 16; ++level) {
        if (std::abs(kPackedLevels[level] - value) < std::abs(kPackedLevels[best] - value)) best = level;
      }
      of[value] = static_cast<std::uint8_t>(best);
    }
  }
  std::uint8_t of[256];
};

const LevelTable& Levels() {
  static const LevelTable table;
  return table;
}

}  // namespace

bool IsPacked(const cv::Mat& descriptors) { return descriptors.type() == CV_8U && descriptors.cols == kPackedColumns; }

cv::Mat PackDescriptors(const cv::Mat& bytes) {
  if (bytes.rows == 0) return cv::Mat(0, kPackedColumns, CV_8U);  // a frame without features
  PATROLMAP_CHECK(bytes.type() == CV_8U && bytes.cols == kDescriptorDimension);
  const std::uint8_t* level = Levels().of;
  cv::Mat packed(bytes.rows, kPackedColumns, CV_8U);
  for (int row = 0; row < bytes.rows; ++row) {
    const std::uint8_t* in = bytes.ptr<std::uint8_t>(row);
    std::uint8_t* out = packed.ptr<std::uint8_t>(row);
    for (int k = 0; k < kPackedColumns; ++k) {
      out[k] = static_cast<std::uint8_t>(level[in[2 * k]] << 4 | level[in[2 * k + 1]]);
    }
  }
  return packed;
}

cv::Mat Expanded(const cv::Mat& descriptors) {
  if (descriptors.rows == 0) return cv::Mat(0, kDescriptorDimension, descriptors.empty() ? CV_8U : descriptors.type());
  if (!IsPacked(descriptors)) return descriptors;
  cv::Mat bytes(descriptors.rows, kDescriptorDimension, CV_8U);
  for (int row = 0; row < descriptors.rows; ++row) {
    const std::uint8_t* in = descriptors.ptr<std::uint8_t>(row);
    std::uint8_t* out = bytes.ptr<std::uint8_t>(row);
    for (int k = 0; k < kPackedColumns; ++k) {
      out[2 * k] = static_cast<std::uint8_t>(kPackedLevels[in[k] >> 4]);
      out[2 * k + 1] = static_cast<std::uint8_t>(kPackedLevels[in[k] & 15]);
    }
  }
  return bytes;
}

void FindNearestTwo(const cv::Mat& query, const cv::Mat& train, std::vector<NearestTwo>* nearest) {
  PATROLMAP_CHECK(query.type() == CV_8U && train.type() == CV_8U && query.cols == kDescriptorDimension &&
                  train.cols == kDescriptorDimension);
  const ByteDistanceFunction distance = FastestByteDistance();
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  nearest->assign(query.rows, NearestTwo());
  for (int i = 0; i < query.rows; ++i) {
    const std::uint8_t* q = query.ptr<std::uint8_t>(i);
    std::uint32_t best = kNone, second = kNone;
    NearestTwo& pair = (*nearest)[i];
    for (int j = 0; j < train.rows; ++j) {
      const std::uint32_t d = distance(q, train.ptr<std::uint8_t>(j));
      if (d < best) {
        second = best, pair.second = pair.first;
        best = d, pair.first = j;
      } else if (d < second) {
        second = d, pair.second = j;
      }
    }
    // Sums of up to 128 squares of 255 stay below 2^24, so the float conversion is exact.
    const auto root = [](std::uint32_t squared) {
      return squared == kNone ? std::numeric_limits<float>::infinity() : std::sqrt(static_cast<float>(squared));
    };
    pair.first_distance = root(best), pair.second_distance = root(second);
  }
}

bool IsStoredDescriptorKind(const cv::Mat& descriptors) {
  if (descriptors.empty()) return true;
  if (descriptors.dims != 2 || descriptors.channels() != 1) return false;
  return (descriptors.depth() == CV_32F && descriptors.cols == kDescriptorDimension) ||
         (descriptors.depth() == CV_8U && (descriptors.cols == kDescriptorDimension || IsPacked(descriptors)));
}

}  // namespace patrolmap::vocab
