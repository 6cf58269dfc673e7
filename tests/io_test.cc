#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "log_capture.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/io/natural_sort.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/io/yaml_file.h"
#include "test_util.h"

namespace patrolmap::io {
namespace {

using testing::LogCapture;
using testing::TempDir;
using testing::WriteText;

cv::Mat TestImage(int value) {
  cv::Mat image(24, 32, CV_8UC1, cv::Scalar(value));
  return image;
}

std::vector<Frame> ReadAll(FrameSource* source, Status* end) {
  std::vector<Frame> frames;
  Frame frame;
  while ((*end = source->Next(true, &frame)).ok()) frames.push_back(frame);
  return frames;
}

// A EuRoC log of `count` frames 50 ms apart, images valued 10, 20, 30, ...
void MakeEurocLog(const std::string& log, int count) {
  std::filesystem::create_directories(log + "/cam0/data");
  std::string table = "#timestamp [ns],filename\n";
  for (int i = 0; i < count; ++i) {
    const std::string name = std::to_string(1000000000LL + i * 50000000LL) + ".png";
    cv::imwrite(log + "/cam0/data/" + name, TestImage(10 * (i + 1)));
    table += std::to_string(1000000000LL + i * 50000000LL) + "," + name + "\n";
  }
  WriteText(log + "/cam0/data.csv", table);
}

TEST(NaturalSort, OrdersDigitRunsByValue) {
  std::vector<std::string> names = {"10.png", "2.png", "1.png", "img10.png", "img9.png", "a.png", "002.png"};
  NaturalSort(&names);
  const std::vector<std::string> expected = {"1.png", "002.png", "2.png", "10.png", "a.png", "img9.png", "img10.png"};
  EXPECT_EQ(names, expected);
}

TEST(Csv, SplitsAndTrims) {
  std::vector<std::string_view> fields;
  SplitCsvLine(" 12 ,abc.png\r", &fields);
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[0], "12");
  EXPECT_EQ(fields[1], "abc.png");
}

TEST(ImageFolder, ReadsInNaturalOrderWithTimestampsFromRate) {
  TempDir dir;
  for (int i : {10, 2, 1}) cv::imwrite(dir / (std::to_string(i) + ".png"), TestImage(i));
  WriteText(dir / "notes.txt", "not an image");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {10.0}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  EXPECT_TRUE(end.end_of_stream());
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].image.at<uchar>(0, 0), 1);
  EXPECT_EQ(frames[1].image.at<uchar>(0, 0), 2);
  EXPECT_EQ(frames[2].image.at<uchar>(0, 0), 10);
  EXPECT_EQ(frames[2].timestamp_ns, 200000000);
}

// A folder without times is read at the assumed rate and says so; one given a rate is timed.
TEST(ImageFolder, WithoutTimesTheRateIsAssumedAndMarked) {
  TempDir dir;
  for (int i : {1, 2}) cv::imwrite(dir / (std::to_string(i) + ".png"), TestImage(i));
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {}, &source).ok());
  EXPECT_FALSE(source->info().timed);
  EXPECT_DOUBLE_EQ(source->info().frame_rate_hz, kAssumedFrameRateHz);
  ASSERT_TRUE(OpenImageFolder(dir.path(), {10.0}, &source).ok());
  EXPECT_TRUE(source->info().timed);
  EXPECT_DOUBLE_EQ(source->info().frame_rate_hz, 10.0);
}

// TUM-style names in seconds with a fraction, and EuRoC-style integer nanoseconds, give times and a rate.
TEST(ImageFolder, NumericFileNamesAreTimes) {
  TempDir dir;
  for (const char* name : {"1305031102.175304.png", "1305031102.275304.png", "1305031102.375304.png"}) {
    cv::imwrite(dir / name, TestImage(1));
  }
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {}, &source).ok());
  EXPECT_TRUE(source->info().timed);
  EXPECT_NEAR(source->info().frame_rate_hz, 10.0, 1e-6);
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].timestamp_ns, 0);
  EXPECT_EQ(frames[2].timestamp_ns, 200000000);
  TempDir ns;
  for (long long t : {1403636579763555584LL, 1403636579813555456LL})
    cv::imwrite(ns / (std::to_string(t) + ".png"), TestImage(1));
  ASSERT_TRUE(OpenImageFolder(ns.path(), {}, &source).ok());
  EXPECT_NEAR(source->info().frame_rate_hz, 20.0, 1e-3);
  TempDir far;  // 13023063657 s is beyond the valid times (fuzzing found the nanoseconds overflowed)
  for (const char* name : {"13023063657.102.png", "13023063658.102.png"}) cv::imwrite(far / name, TestImage(1));
  ASSERT_TRUE(OpenImageFolder(far.path(), {}, &source).ok());
  EXPECT_FALSE(source->info().timed);
  TempDir indices;  // zero-padded frame numbers are indices, not times
  for (const char* name : {"000000.png", "000001.png"}) cv::imwrite(indices / name, TestImage(1));
  ASSERT_TRUE(OpenImageFolder(indices.path(), {}, &source).ok());
  EXPECT_FALSE(source->info().timed);
}

// KITTI keeps one time in seconds per image in times.txt beside the image folder.
TEST(ImageFolder, KittiTimesFileInTheParentFolder) {
  TempDir dir;
  for (int i = 0; i < 3; ++i) cv::imwrite(dir / cv::format("image_0/%06d.png", i), TestImage(i));
  std::filesystem::create_directories(dir / "image_0");
  for (int i = 0; i < 3; ++i) cv::imwrite(dir / cv::format("image_0/%06d.png", i), TestImage(i));
  WriteText(dir / "times.txt", "0.000000e+00\n1.036000e-01\n2.072000e-01\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir / "image_0", {}, &source).ok());
  EXPECT_NEAR(source->info().frame_rate_hz, 1.0 / 0.1036, 1e-6);
  WriteText(dir / "times.txt", "0.0\nsoon\n0.2\n");
  const Status status = OpenImageFolder(dir / "image_0", {}, &source);
  EXPECT_NE(status.message().find("times.txt:2: expected a time in seconds, got 'soon'"), std::string::npos)
      << status.message();
  WriteText(dir / "times.txt", "0.0\n0.1\n1e11\n");  // 1e20 ns: beyond the valid times
  EXPECT_NE(OpenImageFolder(dir / "image_0", {}, &source).message().find("times.txt:3: expected a time in seconds"),
            std::string::npos);
  WriteText(dir / "times.txt", "0.0\n0.1\n");
  EXPECT_NE(OpenImageFolder(dir / "image_0", {}, &source).message().find("2 times for 3 images"), std::string::npos);
}

TEST(ImageFolder, EmptyAndMissingFoldersFailWithTheirName) {
  TempDir dir;
  std::unique_ptr<FrameSource> source;
  Status status = OpenImageFolder(dir.path(), {}, &source);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find(dir.path()), std::string::npos);
  status = OpenLog(dir / "missing", {}, &source);
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_NE(status.message().find("missing"), std::string::npos);
}

TEST(ImagePattern, StartsAtZeroOrOneAndStopsAtTheFirstGap) {
  TempDir dir;
  for (int i : {1, 2, 3, 5}) cv::imwrite(dir / cv::format("f_%03d.png", i), TestImage(i));
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(dir / "f_%03d.png", {}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].image.at<uchar>(0, 0), 3);
  EXPECT_EQ(OpenLog(dir / "g_%03d.png", {}, &source).code(), StatusCode::kNotFound);
}

// Patterns come from the user: anything but one integer conversion is refused, never passed to printf.
TEST(ImagePattern, OnlyOneIntegerConversionIsAccepted) {
  TempDir dir;
  cv::imwrite(dir / "lit%1.png", TestImage(1));
  std::unique_ptr<FrameSource> source;
  for (const char* bad : {"f_%n.png", "f_%s.png", "lit%%.png", "f_%d_%d.png", "f_%999999d.png", "f_%"}) {
    const Status status = OpenLog(dir / bad, {}, &source);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(status.message().find("not an image pattern"), std::string::npos) << status.message();
  }
  ASSERT_TRUE(OpenLog(dir / "lit%%%d.png", {}, &source).ok());  // %% is a percent sign
  Status end;
  EXPECT_EQ(ReadAll(source.get(), &end).size(), 1u);
}

TEST(Video, ReadsGreyFramesAndCountsThem) {
  TempDir dir;
  const std::string path = dir / "clip.avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(64, 48), true);
  if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV build cannot write MJPG video";
  for (int i = 0; i < 6; ++i) writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(40 * i, 40 * i, 40 * i)));
  writer.release();
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(path, {}, &source).ok());
  EXPECT_EQ(source->info().kind, "video");
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(frames[3].image.type(), CV_8UC1);
  EXPECT_NEAR(frames[3].image.at<uchar>(10, 10), 120, 6);
  EXPECT_EQ(frames[5].timestamp_ns, 200000000);  // 5 / 25 Hz
}

// A video cut short (an interrupted copy) is read up to the cut, with a warning that names it and says
// how many of its header's frames are missing.
TEST(Video, TruncatedVideoWarnsAndKeepsItsFrames) {
  TempDir dir;
  const std::string path = dir / "clip.avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(64, 48), true);
  if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV build cannot write MJPG video";
  cv::Mat noise(48, 64, CV_8UC3);
  for (int i = 0; i < 100; ++i) writer.write((cv::randu(noise, 0, 255), noise));
  writer.release();
  std::filesystem::resize_file(path, std::filesystem::file_size(path) * 6 / 10);
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(path, {}, &source).ok());
  LogCapture log;
  Status end;
  const std::size_t frames = ReadAll(source.get(), &end).size();
  EXPECT_GT(frames, 40u);
  EXPECT_LT(frames, 70u);
  EXPECT_NE(log.text().find("clip.avi: the video ends after " + std::to_string(frames) + " of the 100 frames"),
            std::string::npos)
      << log.text();
}

TEST(Video, GarbageFileFails) {
  TempDir dir;
  WriteText(dir / "junk.mp4", "this is not a video");
  std::unique_ptr<FrameSource> source;
  const Status status = OpenLog(dir / "junk.mp4", {}, &source);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("junk.mp4"), std::string::npos);
}

TEST(Euroc, ReadsFramesImuAndSensorYaml) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 4);
  // EuRoC's own sensor.yaml starts with an OpenCV directive that is not YAML.
  WriteText(log + "/cam0/sensor.yaml",
            "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n  data: [0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
            "rate_hz: 20\nresolution: [32, 24]\nintrinsics: [30.0, 31.0, 15.5, 11.5]\n");
  WriteText(log + "/imu0/data.csv",
            "#timestamp,wx,wy,wz,ax,ay,az\n"
            "1000000000,0,0,0.1,0,0,9.8\n1020000000,0,0,0.2,0,0,9.8\n1050000000,0,0,0.3,0,0,9.8\n"
            "1070000000,0,0,0.4,0,0,9.8\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  const LogInfo& info = source->info();
  EXPECT_EQ(info.kind, "euroc");
  EXPECT_EQ(info.frame_count, 4);
  ASSERT_TRUE(info.camera.has_value());
  EXPECT_DOUBLE_EQ(info.camera->fy, 31.0);
  ASSERT_TRUE(info.camera_from_imu.has_value());
  EXPECT_NEAR((*info.camera_from_imu)(0, 1), 1.0, 1e-12);  // transpose of T_BS's rotation
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].imu.size(), 1u);  // t <= 1.00 s
  EXPECT_EQ(frames[1].imu.size(), 2u);  // 1.00 s < t <= 1.05 s
  EXPECT_EQ(frames[2].imu.size(), 1u);
  EXPECT_EQ(frames[3].imu.size(), 0u);
  EXPECT_EQ(frames[2].image.at<uchar>(0, 0), 30);
}

TEST(Euroc, AcceptsTheMav0Folder) {
  TempDir dir;
  MakeEurocLog(dir / "flight/mav0", 2);
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(dir / "flight", {}, &source).ok());
  EXPECT_EQ(source->info().frame_count, 2);
}

// Writes a 3-frame log, replaces `file` (relative to the log) with `text`, and returns what opening says.
Status OpenWithFile(const TempDir& dir, const std::string& file, const std::string& text) {
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  WriteText(log + "/" + file, text);
  std::unique_ptr<FrameSource> source;
  return OpenLog(log, {}, &source);
}

TEST(Euroc, MalformedLineNamesFileAndLine) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n2000x,b.png\n");
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("cam0/data.csv:3: column 'timestamp [ns]': not an integer: '2000x'"),
            std::string::npos)
      << status.message();
}

TEST(Euroc, MissingColumnIsAnError) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "cam0/data.csv", "1000\n");
  EXPECT_NE(status.message().find("data.csv:1: expected at least 2 columns"), std::string::npos) << status.message();
}

TEST(Euroc, NonMonotonicTimestampsAreRejected) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "cam0/data.csv", "1000,a.png\n3000,b.png\n2000,c.png\n");
  EXPECT_NE(status.message().find("data.csv:3: timestamp 2000 is not after the previous one (3000)"), std::string::npos)
      << status.message();
}

// Two frames at one time cannot both be frames of one camera: refused, naming the line (camera tables are
// strict; other sensor tables may repeat a time).
TEST(Euroc, EqualCameraTimestampsAreRejected) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "cam0/data.csv", "1000,a.png\n2000,b.png\n2000,c.png\n");
  EXPECT_NE(status.message().find("data.csv:3: timestamp 2000 is not after the previous one (2000)"), std::string::npos)
      << status.message();
}

// Times beyond 2^62 ns (146 years) or before the epoch would overflow the differences taken of them.
TEST(Euroc, TimestampsOutsideTheValidRangeAreRejected) {
  TempDir dir;
  Status status = OpenWithFile(dir, "cam0/data.csv", "1000,a.png\n9223372036854775807,b.png\n");
  EXPECT_NE(status.message().find("data.csv:2: timestamp 9223372036854775807 is outside 0..4611686018427387904 ns"),
            std::string::npos)
      << status.message();
  TempDir negative;
  status = OpenWithFile(negative, "cam0/data.csv", "-5,a.png\n1000,b.png\n");
  EXPECT_NE(status.message().find("data.csv:1: timestamp -5 is outside"), std::string::npos) << status.message();
}

// A table names files inside its log's data folder; a name that climbs out of it (or is absolute) is
// refused, naming the line, so a log cannot make patrolmap read files elsewhere.
TEST(Euroc, FileNamesOutsideTheDataFolderAreRejected) {
  for (const char* name : {"../../../etc/passwd", "/etc/passwd", "a/../../b.png"}) {
    TempDir dir;
    const Status status = OpenWithFile(dir, "cam0/data.csv", std::string("1000,a.png\n2000,") + name + "\n");
    EXPECT_NE(status.message().find("data.csv:2: file name '" + std::string(name) + "' leaves the log's data folder"),
              std::string::npos)
        << status.message();
  }
  TempDir inside;
  EXPECT_TRUE(OpenWithFile(inside, "cam0/data.csv", "1000,a.png\n2000,sub/../b.png\n").ok());
}

TEST(Euroc, EmptyCameraTableIsAnError) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "cam0/data.csv", "#timestamp [ns],filename\n");
  EXPECT_NE(status.message().find("cam0/data.csv: no frames listed"), std::string::npos) << status.message();
}

TEST(Euroc, MalformedImuLineIsAnError) {
  TempDir dir;
  const Status status = OpenWithFile(dir, "imu0/data.csv", "1000,0,0,0,0,0,9.8\n2000,0,0,zero,0,0,9.8\n");
  EXPECT_NE(status.message().find("imu0/data.csv:2: column 'w_RS_S [rad s^-1]': not a number: 'zero'"),
            std::string::npos)
      << status.message();
}

TEST(Euroc, UnreadableImageInTheMiddleIsCountedAndSkipped) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 5);
  WriteText(log + "/cam0/data/1100000000.png", "truncated png");  // frame 2 corrupt
  std::filesystem::remove(log + "/cam0/data/1150000000.png");     // frame 3 missing
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  EXPECT_TRUE(end.end_of_stream());
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].index, 4);
  EXPECT_EQ(frames[2].image.at<uchar>(0, 0), 50);
  ASSERT_EQ(source->skipped().size(), 2u);
  EXPECT_EQ(source->skipped()[0].index, 2);
  EXPECT_NE(source->skipped()[0].reason.find("1100000000.png"), std::string::npos);
}

TEST(Euroc, SkippingDecodeReturnsEmptyImagesButKeepsOrder) {
  TempDir dir;
  MakeEurocLog(dir / "flight", 3);
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(dir / "flight", {}, &source).ok());
  Frame frame;
  ASSERT_TRUE(source->Next(false, &frame).ok());
  EXPECT_TRUE(frame.image.empty());
  ASSERT_TRUE(source->Next(true, &frame).ok());
  EXPECT_EQ(frame.index, 1);
  EXPECT_EQ(frame.image.at<uchar>(0, 0), 20);
}

TEST(Euroc, SensorYamlOfTheWrongShapeIsRefusedNotThrown) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 1);
  std::unique_ptr<FrameSource> source;
  for (const char* yaml : {"5\n", "- 1\n- 2\n", "intrinsics: [1, 1, 1, 1]\nresolution: [32, 24]\nT_BS: 5\n",
                           "intrinsics: [1, 1, 1, 1]\nresolution: [32, 24]\nT_BS:\n  data: [.nan, 0, 0, 0, 0, 1, 0, 0, "
                           "0, 0, 1, 0, 0, 0, 0, 1]\n"}) {
    WriteText(log + "/cam0/sensor.yaml", yaml);
    const Status status = OpenLog(log, {}, &source);
    EXPECT_EQ(status.code(), StatusCode::kDataLoss) << yaml;
    EXPECT_NE(status.message().find("sensor.yaml"), std::string::npos) << status.message();
  }
  std::filesystem::remove(log + "/cam0/sensor.yaml");
  WriteText(log + "/meta.yaml", "just a scalar\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("meta.yaml: expected a map"), std::string::npos);
}

TEST(Euroc, NonFiniteNumbersInTablesAreRefused) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 2);
  WriteText(log + "/imu0/data.csv", "#t,wx,wy,wz,ax,ay,az\n1000000000,0,0,nan,0,0,9.8\n");
  std::unique_ptr<FrameSource> source;
  Status status = OpenLog(log, {}, &source);
  EXPECT_NE(status.message().find("imu0/data.csv:2:"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("not a finite number"), std::string::npos) << status.message();
  std::filesystem::remove(log + "/imu0/data.csv");
  WriteText(log + "/gps0/data.csv", "#t,lat,lon,alt\n1000000000,1000,8,400\n");
  status = OpenLog(log, {}, &source);
  EXPECT_NE(status.message().find("gps0/data.csv:2: latitude must lie in [-90, 90]"), std::string::npos)
      << status.message();
}

TEST(FlightId, CharactersThatBreakTablesAreReplaced) {
  EXPECT_EQ(CleanFlightId("x,y\nz\"w"), "x_y_z_w");
  EXPECT_EQ(CleanFlightId(""), "flight");
  EXPECT_EQ(CleanFlightId("x</script>"), "x</script>");  // HTML writers escape it
  EXPECT_EQ(CleanFlightId(std::string(500, 'a')).size(), kMaxFlightIdLength);
}

TEST(Euroc, BadSensorYamlNamesTheFile) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 1);
  WriteText(log + "/cam0/sensor.yaml", "intrinsics: [1, 2, 3]\nresolution: [32, 24]\n");
  std::unique_ptr<FrameSource> source;
  Status status = OpenLog(log, {}, &source);
  EXPECT_NE(status.message().find("sensor.yaml: 'intrinsics' must have 4 numbers"), std::string::npos)
      << status.message();
  WriteText(log + "/cam0/sensor.yaml", "intrinsics: [1, 2, 3\n");
  status = OpenLog(log, {}, &source);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("sensor.yaml:"), std::string::npos) << status.message();
  WriteText(log + "/cam0/sensor.yaml", "intrinsics: [1, 2, 3, 4]\nresolution: [32, 24]\nrate_hz: .nan\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("sensor.yaml: 'rate_hz' must be a frame rate above 0"),
            std::string::npos);
  std::filesystem::remove(log + "/cam0/sensor.yaml");
  for (const char* meta : {"frame_rate_hz: -5\n", "frame_rate_hz: [30]\n"}) {
    WriteText(log + "/meta.yaml", meta);
    EXPECT_NE(OpenLog(log, {}, &source).message().find("meta.yaml: 'frame_rate_hz' must be a frame rate above 0"),
              std::string::npos)
        << meta;
  }
  WriteText(log + "/meta.yaml", "flight_id: {a: 1}\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("meta.yaml: 'flight_id' must be text"), std::string::npos);
}

// YAML forbids a key twice in one map, and yaml-cpp would keep one silently: refused at any depth, naming
// the file, line and key (sensor.yaml, meta.yaml and configurations all load this way).
TEST(Yaml, ARepeatedKeyIsRefusedNamingFileLineAndKey) {
  TempDir dir;
  YAML::Node root;
  WriteText(dir / "a.yaml", "rate_hz: 20\nT_BS:\n  rows: 4\n  rows: 5\n");
  Status status = LoadYamlFile(dir / "a.yaml", &root);
  EXPECT_NE(status.message().find("a.yaml:4: key 'rows' appears twice in one map"), std::string::npos)
      << status.message();
  WriteText(dir / "b.yaml", "- {x: 1}\n- {x: 1, x: 2}\n");
  EXPECT_NE(LoadYamlFile(dir / "b.yaml", &root).message().find("b.yaml:2: key 'x' appears twice"), std::string::npos);
  WriteText(dir / "d.yaml", "flow:\n  ? {edges: 1}\n  : 2\n");  // a map as a key (fuzzing found it threw)
  EXPECT_NE(LoadYamlFile(dir / "d.yaml", &root).message().find("d.yaml:2: a key must be a plain name"),
            std::string::npos)
      << LoadYamlFile(dir / "d.yaml", &root).message();
  WriteText(dir / "c.yaml", "a: {x: 1}\nb: {x: 1}\n");  // the same key in two maps is fine
  EXPECT_TRUE(LoadYamlFile(dir / "c.yaml", &root).ok());
}

TEST(Euroc, SpeedIsInterpolatedFromTheStateTable) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  WriteText(log + "/state_groundtruth_estimate0/data.csv",
            "1000000000,0,0,0,1,0,0,0,3,4,0\n1100000000,0,0,0,1,0,0,0,0,1,0\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_TRUE(frames[1].speed_mps.has_value());
  EXPECT_DOUBLE_EQ(*frames[0].speed_mps, 5.0);
  EXPECT_DOUBLE_EQ(*frames[1].speed_mps, 3.0);  // halfway between 5 and 1
  EXPECT_DOUBLE_EQ(*frames[2].speed_mps, 1.0);
}

TEST(Euroc, GpsIsInterpolatedAtFrameTimes) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  WriteText(log + "/gps0/data.csv", "#t,lat,lon,alt\n1000000000,47.0,8.0,500\n1100000000,47.0002,8.0004,510\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_TRUE(frames[1].gps.has_value());
  EXPECT_NEAR(frames[1].gps->x(), 47.0001, 1e-12);
  EXPECT_NEAR(frames[1].gps->y(), 8.0002, 1e-12);
  EXPECT_NEAR(frames[1].gps->z(), 505.0, 1e-9);
  WriteText(log + "/gps0/data.csv", "1000000000,47.0,8.0\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("gps0/data.csv:1: expected at least 4 columns"),
            std::string::npos);
}

TEST(PatrolSensors, PosesDetectionsAndDepthOfALog) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  // A camera looking along body +x: T_BS maps camera axes to body axes x_c -> -y_b, y_c -> -z_b, z_c -> +x_b.
  WriteText(log + "/cam0/sensor.yaml",
            "T_BS:\n  cols: 4\n  rows: 4\n  data: [0, 0, 1, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 1]\n"
            "rate_hz: 20\nresolution: [32, 24]\nintrinsics: [20, 20, 15.5, 11.5]\n");
  // Body yawed by 90 degrees (facing +y) at the first row, moving 1 m along +y by the second.
  const double h = std::sqrt(0.5);
  WriteText(log + "/state_groundtruth_estimate0/data.csv",
            "1000000000,0,0,2," + std::to_string(h) + ",0,0," + std::to_string(h) + ",0,0,0\n" + "1100000000,0,1,2," +
                std::to_string(h) + ",0,0," + std::to_string(h) + ",0,0,0\n");
  WriteText(log + "/objects0/data.csv",
            "#t,label,confidence,x0,y0,x1,y1,x,y,z\n1000000000,crate,0.8,1,2,11,12,0.5,0.25,6\n"
            "1000000000,barrel,0.6,20,2,25,9\n1050000000,crate,0.7,2,2,12,12,0.5,0.25,5.5\n");
  std::filesystem::create_directories(log + "/depth0/data");
  cv::imwrite(log + "/depth0/data/d.png", cv::Mat(24, 32, CV_16UC1, cv::Scalar(4500)));
  WriteText(log + "/depth0/data.csv", "#t,filename\n1000000000,d.png\n");
  PatrolSensors sensors;
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  ASSERT_EQ(sensors.poses.size(), 2u);
  // The camera axis (z) points along world +y; a point 6 m ahead lies at (0, 6, 2).
  const Eigen::Vector3d ahead = sensors.poses[0].ToWorld(Eigen::Vector3d(0, 0, 6));
  EXPECT_LT((ahead - Eigen::Vector3d(0, 6, 2)).norm(), 1e-9);
  const Eigen::Vector3d right = sensors.poses[0].ToWorld(Eigen::Vector3d(1, 0, 0)) - sensors.poses[0].position;
  EXPECT_LT((right - Eigen::Vector3d(1, 0, 0)).norm(), 1e-9);  // facing +y, the camera's right is +x
  const std::optional<CameraPoseSample> halfway = PoseAt(sensors.poses, 1050000000);
  ASSERT_TRUE(halfway.has_value());
  EXPECT_NEAR(halfway->position.y(), 0.5, 1e-12);
  EXPECT_FALSE(PoseAt(sensors.poses, 1200000000).has_value());
  EXPECT_FALSE(PoseAt(sensors.poses, 1050000000, 50000000).has_value());  // a gap longer than allowed
  ASSERT_EQ(sensors.detections.size(), 3u);
  EXPECT_EQ(sensors.detections[1].label, "barrel");
  EXPECT_FALSE(sensors.detections[1].centroid_camera.has_value());
  EXPECT_DOUBLE_EQ(sensors.detections[0].centroid_camera->z(), 6.0);
  EXPECT_DOUBLE_EQ(sensors.detections[0].box.width, 10.0);
  ASSERT_EQ(sensors.depth.size(), 1u);
  cv::Mat depth;
  ASSERT_TRUE(ReadDepthImage(sensors.depth[0].path, &depth).ok());
  EXPECT_FLOAT_EQ(depth.at<float>(3, 4), 4.5f);
  ASSERT_TRUE(sensors.camera.has_value());
  EXPECT_EQ(sensors.camera->width, 32);
  // Depth images the table lists but the log lacks are dropped with one warning naming the first.
  WriteText(log + "/depth0/data.csv", "#t,filename\n1000000000,d.png\n1100000000,gone.png\n1200000000,6\n");
  LogCapture capture;
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  EXPECT_EQ(sensors.depth.size(), 1u);
  EXPECT_NE(capture.text().find("depth0/data.csv: 2 of the 3 depth images it lists are missing (the first: " + log +
                                "/depth0/data/gone.png); they are skipped"),
            std::string::npos)
      << capture.text();
}

TEST(PatrolSensors, BadTablesNameFileAndLine) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 2);
  PatrolSensors sensors;
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,1,2,11,12\n1000000000,crate,1.7,1,2,11,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("objects0/data.csv:2: confidence must lie in [0, 1]"),
            std::string::npos);
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,11,2,1,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("x_max > x_min"), std::string::npos);
  WriteText(log + "/objects0/data.csv", "1000000000,crate,0.8,1,2,11,12\n900000000,crate,0.8,1,2,11,12\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("objects0/data.csv:2: timestamp 900000000 is before"),
            std::string::npos);
  std::filesystem::remove(log + "/objects0/data.csv");
  WriteText(log + "/state_groundtruth_estimate0/data.csv", "1000000000,0,0,2,0.5,0,0,0,0,0,0\n");
  EXPECT_NE(ReadPatrolSensors(log, &sensors).message().find("q_RS is not a unit quaternion"), std::string::npos);
  std::filesystem::remove(log + "/state_groundtruth_estimate0/data.csv");
  std::filesystem::create_directories(log + "/depth0/data");
  cv::imwrite(log + "/depth0/data/d.png", TestImage(9));
  WriteText(log + "/depth0/data.csv", "1000000000,d.png\n");
  ASSERT_TRUE(ReadPatrolSensors(log, &sensors).ok());
  cv::Mat depth;
  EXPECT_NE(ReadDepthImage(sensors.depth[0].path, &depth).message().find("d.png: depth image must be 16-bit"),
            std::string::npos);
  EXPECT_EQ(ReadDepthImage(dir / "none.png", &depth).code(), StatusCode::kNotFound);
}

TEST(Euroc, RealSensorYamlFromSharedData) {
  const std::string path = std::string(PATROLMAP_SOURCE_DIR) + "/../shared/data/euroc_revisit_pairs/sensorLeft.yaml";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not present";
  YAML::Node root;
  ASSERT_TRUE(LoadYamlFile(path, &root).ok());
  EXPECT_DOUBLE_EQ(root["intrinsics"][0].as<double>(), 458.654);
}

}  // namespace
}  // namespace patrolmap::io
