#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/image_header.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/rate_gate.h"
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

// A process ended by SIGTERM while it writes a file leaves the previous file and no temporary.
TEST(AtomicFile, ASignalWhileWritingRemovesTheTemporary) {
  testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir / "map.pmap", "previous").ok());
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    RemoveTemporariesOnSignal();
    AtomicFile file;
    if (!AtomicFile::Open(dir / "map.pmap", &file).ok() || !file.Write("half of a new map").ok()) ::_exit(3);
    std::raise(SIGTERM);
    ::_exit(4);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(testing::ReadText(dir / "map.pmap"), "previous");
  int files = 0;
  for (const auto& item : std::filesystem::directory_iterator(dir.path())) files += item.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(DeclaredImageSize, PngAndJpegHeadersAreReadWithoutDecoding) {
  std::int64_t width = 0, height = 0;
  // PNG: the signature, then IHDR's length, type, width and height (big endian).
  const std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', 13, 10, 26,   10,   0, 0, 0,    13,
                                          'I',  'H', 'D', 'R', 0,  0,  0x3E, 0x80, 0, 0, 0x1F, 0x40};
  ASSERT_TRUE(DeclaredImageSize(png.data(), png.size(), &width, &height));
  EXPECT_EQ(width, 16000);
  EXPECT_EQ(height, 8000);
  EXPECT_FALSE(DeclaredImageSize(png.data(), png.size() - 1, &width, &height));  // cut inside the size
  // JPEG: start of image, an APP0 segment, a fill byte, then SOF0 (precision, height, width).
  std::vector<unsigned char> jpeg = {0xFF, 0xD8, 0xFF, 0xE0, 0,    4,    'J',  'F',  0xFF, 0xFF,
                                     0xC0, 0,    11,   8,    0x20, 0x00, 0x10, 0x00, 1};
  ASSERT_TRUE(DeclaredImageSize(jpeg.data(), jpeg.size(), &width, &height));
  EXPECT_EQ(width, 4096);
  EXPECT_EQ(height, 8192);
  jpeg[10] = 0xDA;  // the scan starts before any frame header
  EXPECT_FALSE(DeclaredImageSize(jpeg.data(), jpeg.size(), &width, &height));
  const std::vector<unsigned char> text = {'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'a', 'g', 'e'};
  EXPECT_FALSE(DeclaredImageSize(text.data(), text.size(), &width, &height));
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

// OpenCV's radial-tangential model, worked by hand for one point: x = 0.5, y = -0.25 (r^2 = 0.3125).
TEST(Distortion, RadialAndTangentialTermsAsOpenCvDefinesThem) {
  const Eigen::Vector2d point(0.5, -0.25);
  EXPECT_TRUE(Distorted(Distortion{}, point).isApprox(point));
  // radial 1 - 0.2 * 0.3125 + 0.05 * 0.09765625 = 0.942382812; x: 0.471191406 + 2 * 0.01 * (-0.125) +
  // 0.02 * (0.3125 + 0.5) = 0.484941406; y: -0.235595703 + 0.01 * (0.3125 + 0.125) + 2 * 0.02 * (-0.125) =
  // -0.236220703.
  bool folded = true;
  const Eigen::Vector2d seen = Distorted({-0.2, 0.05, 0.01, 0.02}, point, &folded);
  EXPECT_FALSE(folded);
  EXPECT_NEAR(seen.x(), 0.484941406, 1e-9);
  EXPECT_NEAR(seen.y(), -0.236220703, 1e-9);
  // k1 -0.5: the radial term stops growing at r^2 = 2/3; a point beyond is returned as it was.
  EXPECT_TRUE(Distorted({-0.5, 0.0, 0.0, 0.0}, Eigen::Vector2d(1.0, 0.0), &folded).isApprox(Eigen::Vector2d(1, 0)));
  EXPECT_TRUE(folded);
}

// A box beside the optical axis lands nearer the centre through a barrel lens (k1 < 0) than through a pinhole.
TEST(Distortion, ProjectedCornersFollowTheLens) {
  const CameraIntrinsics camera{400.0, 400.0, 320.0, 240.0, 640, 480};
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) corners[i] = Eigen::Vector3d(2.0 + (i & 1), -0.5 + ((i >> 1) & 1), 5.0 + (i >> 2));
  const cv::Rect2d pinhole = ProjectCorners(camera, CameraPoseSample(), corners);
  const cv::Rect2d barrel = ProjectCorners(camera, CameraPoseSample(), corners, {-0.28, 0.07, 0.0, 0.0});
  EXPECT_NEAR(pinhole.x, 320.0 + 400.0 * 2.0 / 6.0, 1e-9);  // the nearest left corner at x 2, z 6
  EXPECT_LT(barrel.br().x, pinhole.br().x - 10.0);
  EXPECT_LT(barrel.x, pinhole.x);
}

TEST(Time, SecondsAndNanosecondsRoundTrip) {
  EXPECT_EQ(SecondsToNs(1.5), 1500000000);
  EXPECT_EQ(SecondsToNs(-0.25), -250000000);
  EXPECT_DOUBLE_EQ(NsToSeconds(2500000000), 2.5);
}

// The frames a gate at `rate_hz` takes from `count` frames at the times `time_of` gives.
template <typename TimeOf>
std::vector<int> TakenFrames(double rate_hz, int count, TimeOf time_of) {
  RateGate gate(rate_hz);
  std::vector<int> taken;
  for (int i = 0; i < count; ++i) {
    if (!gate.Due(time_of(i))) continue;
    gate.Take(time_of(i));
    taken.push_back(i);
  }
  return taken;
}

// A 30 Hz log's times are rounded to the nanosecond: 15 Hz takes every second frame (a gate that waits a whole step
// after the frame taken takes every third), 10 Hz every third, 5 Hz every sixth.
TEST(RateGate, TakesEveryNthFrameOfARoundedLog) {
  const auto at_30_hz = [](int i) { return SecondsToNs(i / 30.0); };
  for (const int every : {1, 2, 3, 6}) {
    const std::vector<int> taken = TakenFrames(30.0 / every, 300, at_30_hz);
    ASSERT_EQ(taken.size(), 300u / every) << every;
    for (std::size_t k = 0; k < taken.size(); ++k) EXPECT_EQ(taken[k], static_cast<int>(k) * every) << every;
  }
}

// Jittered times (a 20 Hz camera, +-1.5 ms) keep the rate on average; a frame a little early is taken, a gap starts
// the schedule again at the next frame, and a frame not used (Due without Take) leaves the schedule as it was.
TEST(RateGate, KeepsTheRateOfAJitteredLogAndRestartsAfterAGap) {
  const auto jittered = [](int i) { return SecondsToNs(1.0 + i * 0.05 + ((i * 7) % 3 - 1) * 0.0015); };
  EXPECT_EQ(TakenFrames(5.0, 400, jittered).size(), 100u);  // 20 s of flight
  const auto with_gap = [](int i) { return SecondsToNs(i < 10 ? i * 0.05 : 10.0 + i * 0.05); };
  const std::vector<int> taken = TakenFrames(5.0, 30, with_gap);
  EXPECT_EQ(taken, (std::vector<int>{0, 4, 8, 10, 14, 18, 22, 26}));
  RateGate gate(5.0);
  gate.Take(0);
  EXPECT_FALSE(gate.Due(SecondsToNs(0.197)));
  EXPECT_TRUE(gate.Due(SecondsToNs(0.1985)));  // within a hundredth of the step
  EXPECT_TRUE(gate.Due(SecondsToNs(0.25)));
  gate.Take(SecondsToNs(0.25));
  EXPECT_TRUE(gate.Due(SecondsToNs(0.399)));  // the schedule, not the frame taken, sets the next time
}

}  // namespace
}  // namespace patrolmap
