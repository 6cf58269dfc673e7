#include <filesystem>

#include <gtest/gtest.h>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/types.h"
#include "test_util.h"

namespace patrolmap {
namespace {

// Map sections are checksummed as they are streamed to the file: any split gives the one-shot checksum.
TEST(ChecksumStream, AnySplitGivesTheWholeChecksum) {
  std::string data;
  for (int i = 0; i < 1000; ++i) data.push_back(static_cast<char>((i * 7919) % 251));
  for (std::size_t size : {0, 1, 7, 8, 9, 63, 1000}) {
    const std::uint64_t whole = Checksum(data.data(), size);
    for (std::size_t piece : {1, 3, 8, 13, 64}) {
      ChecksumStream stream(size);
      for (std::size_t at = 0; at < size; at += piece) stream.Add(data.data() + at, std::min(piece, size - at));
      EXPECT_EQ(stream.Finish(), whole) << size << " bytes in pieces of " << piece;
    }
  }
  EXPECT_NE(Checksum(data.data(), 9), Checksum(data.data(), 8));
}

TEST(Csv, SplitsAndTrims) {
  std::vector<std::string_view> fields;
  SplitCsvLine(" 12 ,abc.png\r", &fields);
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[0], "12");
  EXPECT_EQ(fields[1], "abc.png");
}

TEST(WriteFileAtomically, WritesAndReplacesWithoutLeavingTemporaries) {
  testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir / "a.txt", "first").ok());
  ASSERT_TRUE(WriteFileAtomically(dir / "a.txt", "second").ok());
  EXPECT_EQ(testing::ReadText(dir / "a.txt"), "second");
  int files = 0;
  for (const auto& item : std::filesystem::directory_iterator(dir.path())) files += item.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(WriteFileAtomically, MissingFolderFailsAndNamesThePath) {
  testing::TempDir dir;
  const Status status = WriteFileAtomically(dir / "no/such/folder/a.txt", "x");
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find("no/such/folder"), std::string::npos);
}

TEST(CameraIntrinsics, ScalingKeepsPixelCentresAligned) {
  const CameraIntrinsics camera{458.0, 456.0, 367.5, 239.5, 752, 480};
  const CameraIntrinsics half = camera.Scaled(0.5);
  EXPECT_DOUBLE_EQ(half.fx, 229.0);
  EXPECT_DOUBLE_EQ(half.fy, 228.0);
  EXPECT_DOUBLE_EQ(half.cx, 183.5);  // (367.5 + 0.5) / 2 - 0.5
  EXPECT_DOUBLE_EQ(half.cy, 119.5);
  EXPECT_EQ(half.width, 376);
  EXPECT_EQ(half.height, 240);
}

TEST(Time, SecondsAndNanosecondsRoundTrip) {
  EXPECT_EQ(SecondsToNs(1.5), 1500000000);
  EXPECT_EQ(SecondsToNs(-0.25), -250000000);
  EXPECT_DOUBLE_EQ(NsToSeconds(2500000000), 2.5);
}

}  // namespace
}  // namespace patrolmap
