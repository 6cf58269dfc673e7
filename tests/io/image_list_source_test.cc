#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "io/fixtures.h"
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
using testing_fixtures::ReadAll;
using testing_fixtures::TestImage;

TEST(ImageFolder, ReadsInNaturalOrderWithTimestampsFromRate) {
  TempDir dir;
  for (int i : {10, 2, 1}) cv::imwrite(dir / (std::to_string(i) + ".png"), TestImage(i));
  WriteText(dir / "notes.txt", "not an image");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {10.0, {}}, &source).ok());
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  EXPECT_TRUE(end.end_of_stream());
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].image.at<uchar>(0, 0), 1);
  EXPECT_EQ(frames[1].image.at<uchar>(0, 0), 2);
  EXPECT_EQ(frames[2].image.at<uchar>(0, 0), 10);
  EXPECT_EQ(frames[2].timestamp_ns, 200000000);
}

// Asked for it, a colour image keeps its colour beside the grey one; grey images and frames read without
// asking have none.
TEST(ImageFolder, KeepsTheColourImageWhenAsked) {
  TempDir dir;
  cv::imwrite(dir / "0.png", cv::Mat(24, 32, CV_8UC3, cv::Scalar(10, 100, 200)));
  cv::imwrite(dir / "1.png", TestImage(7));
  cv::imwrite(dir / "2.png", cv::Mat(24, 32, CV_8UC3, cv::Scalar(10, 100, 200)));
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {10.0, {}}, &source).ok());
  Frame frame;
  source->KeepColour(true);
  ASSERT_TRUE(source->Next(true, &frame).ok());
  ASSERT_EQ(frame.colour.type(), CV_8UC3);
  EXPECT_EQ(frame.colour.at<cv::Vec3b>(2, 3), cv::Vec3b(10, 100, 200));
  EXPECT_EQ(frame.image.type(), CV_8UC1);
  EXPECT_NEAR(frame.image.at<uchar>(2, 3), 0.114 * 10 + 0.587 * 100 + 0.299 * 200, 1.0);
  ASSERT_TRUE(source->Next(true, &frame).ok());
  EXPECT_TRUE(frame.colour.empty());  // a grey image
  source->KeepColour(false);
  ASSERT_TRUE(source->Next(true, &frame).ok());
  EXPECT_TRUE(frame.colour.empty());
  EXPECT_EQ(frame.image.type(), CV_8UC1);
}

// A folder without times is read at the assumed rate and says so; one given a rate is timed.
TEST(ImageFolder, WithoutTimesTheRateIsAssumedAndMarked) {
  TempDir dir;
  for (int i : {1, 2}) cv::imwrite(dir / (std::to_string(i) + ".png"), TestImage(i));
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir.path(), {}, &source).ok());
  EXPECT_FALSE(source->info().timed);
  EXPECT_DOUBLE_EQ(source->info().frame_rate_hz, kAssumedFrameRateHz);
  ASSERT_TRUE(OpenImageFolder(dir.path(), {10.0, {}}, &source).ok());
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

// An image folder has no calibration of its own; --camera gives it one (a EuRoC sensor.yaml), lens and all.
TEST(ImageFolder, TakesItsCameraFromACameraFile) {
  TempDir dir;
  std::filesystem::create_directories(dir / "images");
  for (int i : {1, 2}) cv::imwrite(dir / ("images/" + std::to_string(i) + ".png"), TestImage(i));  // 32x24
  const std::string intrinsics = "intrinsics: [30.0, 31.0, 15.5, 11.5]\n";
  WriteText(dir / "cam.yaml", intrinsics +
                                  "resolution: [32, 24]\ndistortion_model: radial-tangential\n"
                                  "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenImageFolder(dir / "images", {10.0, {}}, &source).ok());
  EXPECT_FALSE(source->info().camera.has_value());
  ASSERT_TRUE(source->UseCameraFile(dir / "cam.yaml").ok());
  ASSERT_TRUE(source->info().camera.has_value());
  EXPECT_DOUBLE_EQ(source->info().camera->fy, 31.0);
  EXPECT_EQ(source->info().camera_distortion, (Distortion{-0.28, 0.07, 0.0002, 0.00002}));
  const auto refused = [&](const std::string& text) {
    WriteText(dir / "bad.yaml", text);
    return source->UseCameraFile(dir / "bad.yaml").message();
  };
  EXPECT_NE(refused(intrinsics + "resolution: [64, 48]\n").find("bad.yaml: resolution 64x48, but "), std::string::npos);
  EXPECT_NE(refused(intrinsics + "resolution: [32, 24]\ndistortion_model: equidistant\n")
                .find("bad.yaml: distortion_model 'equidistant' is not radial-tangential"),
            std::string::npos);
  EXPECT_NE(refused("resolution: [32, 24]\n").find("bad.yaml"), std::string::npos);
  EXPECT_NE(refused(intrinsics + "resolution: [1e12, 24]\n").find("bad.yaml: 'resolution' must be whole numbers"),
            std::string::npos);
  EXPECT_NE(refused("intrinsics: [.inf, 30, 15.5, 11.5]\nresolution: [32, 24]\n").find("not a finite number"),
            std::string::npos);
  EXPECT_NE(refused(intrinsics + "resolution: [32, 24]\ndistortion_coefficients: [0.1, 0.2]\n").find("bad.yaml"),
            std::string::npos);
  EXPECT_FALSE(source->UseCameraFile(dir / "missing.yaml").ok());
  EXPECT_DOUBLE_EQ(source->info().camera->fy, 31.0);  // a refused file leaves the camera as it was
}

TEST(Video, RefusesACameraFile) {
  TempDir dir;
  const std::string video = dir / "clip.avi";
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(32, 24), false);
  if (!writer.isOpened()) GTEST_SKIP() << "no MJPG writer";
  for (int i = 0; i < 3; ++i) writer.write(TestImage(10 * i));
  writer.release();
  WriteText(dir / "cam.yaml", "intrinsics: [30, 30, 15.5, 11.5]\nresolution: [32, 24]\n");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(video, {}, &source).ok());
  EXPECT_NE(source->UseCameraFile(dir / "cam.yaml").message().find("not a video"), std::string::npos);
}

}  // namespace
}  // namespace patrolmap::io
