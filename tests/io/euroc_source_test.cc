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

using testing::TempDir;
using testing::WriteText;
using testing_fixtures::MakeEurocLog;
using testing_fixtures::ReadAll;

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
  EXPECT_EQ(info.camera_distortion, Distortion{});  // none given
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
                           "0, 0, 1, 0, 0, 0, 0, 1]\n",
                           "intrinsics: [1, 1, 1, 1]\nresolution: [32, 24]\nT_BS:\n  data: [0, 0, 0, 0, 0, 0, 0, 0, 0, "
                           "0, 0, 0, 0, 0, 0, 0]\n",
                           "intrinsics: [1, 1, 1, 1]\nresolution: [32, 24]\nT_BS:\n  data: [-1, 0, 0, 0, 0, 1, 0, 0, "
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
  EXPECT_EQ(CleanFlightId("x<script>"), "x<script>");  // HTML writers escape it
  EXPECT_EQ(CleanFlightId(std::string(500, 'a')).size(), kMaxFlightIdLength);
}

TEST(FlightId, IdsNeverNameAFolderOutsideTheOutputOrBreakUtf8) {
  EXPECT_EQ(CleanFlightId("../../../x"), ".._.._.._x");
  EXPECT_EQ(CleanFlightId(".."), "__");
  EXPECT_EQ(CleanFlightId("."), "_");
  EXPECT_EQ(CleanFlightId("a\\b"), "a_b");
  EXPECT_EQ(CleanFlightId("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 stays
  EXPECT_EQ(CleanFlightId("x\xffy"), "x_y");
  EXPECT_EQ(CleanFlightId("x\xc3"), "x_");  // a character cut short
  EXPECT_FALSE(IsValidFlightId("x\xffy"));
  EXPECT_FALSE(IsValidFlightId(".."));
  // Two long ids that share their first 200 bytes stay two ids, and a cut never splits a character.
  const std::string start(190, 'a'), accented = std::string(199, 'a') + "\xc3\xa9" + "tail";
  EXPECT_NE(CleanFlightId(start + std::string(50, 'x')), CleanFlightId(start + std::string(50, 'y')));
  for (const std::string& raw : {start + std::string(50, 'x'), accented}) {
    const std::string id = CleanFlightId(raw);
    EXPECT_LE(id.size(), kMaxFlightIdLength);
    EXPECT_TRUE(IsValidFlightId(id)) << id;
  }
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

// A log without a state estimate whose IMU reports its attitude (imu0/'s columns 8-11, w x y z): the camera poses
// come from gps0/ and that attitude, at the frames' times.
TEST(Euroc, PosesFromGpsAndTheImusAttitude) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);  // frames at 1.00, 1.05 and 1.10 s
  // The camera looks along the body's x axis (EuRoC's T_BS rotation: camera axes into the body's).
  WriteText(log + "/cam0/sensor.yaml",
            "T_BS:\n  data: [0, 0, 1, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 1]\n"
            "resolution: [32, 24]\nintrinsics: [30.0, 30.0, 15.5, 11.5]\n");
  const double c = std::cos(M_PI / 12), s = std::sin(M_PI / 12);  // 30 degrees about up
  WriteText(log + "/imu0/data.csv", "#t,wx,wy,wz,ax,ay,az,qw,qx,qy,qz\n1000000000,0,0,0,0,0,9.8,1,0,0,0\n" +
                                        std::string("1100000000,0,0,0,0,0,9.8,") + std::to_string(c) + ",0,0," +
                                        std::to_string(s) + "\n");
  WriteText(log + "/gps0/data.csv", "#t,lat,lon,alt\n1000000000,47.03,8.04,500\n1100000000,47.0302,8.04,510\n");
  testing::LogCapture capture;
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_TRUE(source->info().has_poses);
  EXPECT_EQ(source->info().pose_source, kPosesFromGps);
  EXPECT_NE(capture.text().find("camera poses from gps0/ and imu0/'s attitude at 3 of 3 frames"), std::string::npos)
      << capture.text();
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_TRUE(frames[1].pose.has_value());
  const double metres_per_degree = M_PI / 180.0 * 6378137.0;  // about the grid point 47.0, 8.0
  EXPECT_NEAR(frames[1].pose->position.y(), 0.0301 * metres_per_degree, 1e-6);
  EXPECT_NEAR(frames[1].pose->position.x(), 0.04 * metres_per_degree * std::cos(47.0 * M_PI / 180.0), 1e-6);
  EXPECT_NEAR(frames[1].pose->position.z(), 505.0, 1e-9);
  // Halfway: 15 degrees about up; the camera's optical axis (z) along the body's x axis, turned by it.
  const Eigen::Vector3d axis = frames[1].pose->rotation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(axis.x(), std::cos(M_PI / 12), 1e-6);
  EXPECT_NEAR(axis.y(), std::sin(M_PI / 12), 1e-6);
  EXPECT_NEAR(axis.z(), 0.0, 1e-9);

  // A state estimate takes precedence.
  WriteText(log + "/state_groundtruth_estimate0/data.csv",
            "#t,px,py,pz,qw,qx,qy,qz,vx,vy,vz\n1000000000,1,2,3,1,0,0,0,0,0,0\n1100000000,1,2,3,1,0,0,0,0,0,0\n");
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_EQ(source->info().pose_source, kPosesFromStateEstimate);
  const std::vector<Frame> estimated = ReadAll(source.get(), &end);
  ASSERT_TRUE(estimated[1].pose.has_value());
  EXPECT_TRUE(estimated[1].pose->position.isApprox(Eigen::Vector3d(1, 2, 3)));
  // Without cam0/sensor.yaml the camera's rotation in the IMU's frame is unknown.
  std::filesystem::remove_all(log + "/state_groundtruth_estimate0");
  std::filesystem::remove(log + "/cam0/sensor.yaml");
  testing::LogCapture second;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_FALSE(source->info().has_poses);
  EXPECT_NE(second.text().find("cam0/sensor.yaml is missing"), std::string::npos) << second.text();
  WriteText(log + "/imu0/data.csv", "#t,wx,wy,wz,ax,ay,az,qw,qx,qy,qz\n1000000000,0,0,0,0,0,9.8,1,0,0,0.5\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("imu0/data.csv:2: q_WS (attitude) is not a unit quaternion"),
            std::string::npos);
  WriteText(log + "/imu0/data.csv", "#t,wx,wy,wz,ax,ay,az,qw,qx,qy,qz\n1000000000,0,0,0,0,0,9.8,1,0\n");
  EXPECT_NE(
      OpenLog(log, {}, &source).message().find("imu0/data.csv:2: expected 7 columns, or 11 with the attitude, found 9"),
      std::string::npos);
}

// cam0 and cam1 0.11 m apart (EuRoC's layout): cam1's images at cam0's times make stereo pairs.
void AddStereoCamera(const std::string& log, const std::string& cam1_model) {
  const std::string intrinsics = "resolution: [32, 24]\nintrinsics: [30.0, 30.0, 15.5, 11.5]\n";
  WriteText(log + "/cam0/sensor.yaml",
            "T_BS:\n  data: [1, 0, 0, 0.01, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n" + intrinsics +
                "distortion_model: radial-tangential\ndistortion_coefficients: [0.01, -0.002, 0.0001, 0.0002]\n");
  WriteText(log + "/cam1/sensor.yaml", "T_BS:\n  data: [1, 0, 0, 0.12, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n" +
                                           intrinsics + "distortion_model: " + cam1_model + "\n");
  std::filesystem::create_directories(log + "/cam1/data");
  // cam1 misses cam0's second frame.
  WriteText(log + "/cam1/data.csv", "#timestamp [ns],filename\n1000000000,a.png\n1100000000,c.png\n");
}

TEST(Euroc, Cam1MakesStereoPairsAtCam0sTimes) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  AddStereoCamera(log, "radial-tangential");
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  const LogInfo& info = source->info();
  ASSERT_TRUE(info.has_stereo);
  EXPECT_NEAR(info.stereo->right_from_left_translation.x(), -0.11, 1e-12);
  EXPECT_DOUBLE_EQ(info.stereo->left_distortion[0], 0.01);
  EXPECT_DOUBLE_EQ(info.stereo->left_distortion[3], 0.0002);
  EXPECT_EQ(info.camera_distortion, info.stereo->left_distortion);  // cam0's lens, for its route frames too
  Status end;
  const std::vector<Frame> frames = ReadAll(source.get(), &end);
  ASSERT_EQ(frames.size(), 3u);
  ASSERT_EQ(frames[0].depth.size(), 1u);
  EXPECT_TRUE(frames[0].depth[0].stereo());
  EXPECT_EQ(frames[0].depth[0].right_path, log + "/cam1/data/a.png");
  EXPECT_EQ(frames[0].depth[0].path, log + "/cam0/data/1000000000.png");
  EXPECT_TRUE(frames[1].depth.empty());
  ASSERT_EQ(frames[2].depth.size(), 1u);
  EXPECT_EQ(frames[2].depth[0].right_path, log + "/cam1/data/c.png");
}

TEST(Euroc, AStereoCameraOfAnotherModelIsLeftOutNamingItsFile) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 3);
  AddStereoCamera(log, "equidistant");
  testing::LogCapture capture;
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_FALSE(source->info().has_stereo);
  EXPECT_NE(capture.text().find("cam1/sensor.yaml: distortion_model 'equidistant'"), std::string::npos)
      << capture.text();
}

TEST(Euroc, Cam0OfAnotherModelIsTakenForUndistortedNamingItsFile) {
  TempDir dir;
  const std::string log = dir / "flight";
  MakeEurocLog(log, 2);
  WriteText(log + "/cam0/sensor.yaml",
            "resolution: [32, 24]\nintrinsics: [30.0, 30.0, 15.5, 11.5]\ndistortion_model: equidistant\n"
            "distortion_coefficients: [0.1, 0.01, 0.001, 0.0001]\n");
  testing::LogCapture capture;
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(OpenLog(log, {}, &source).ok());
  EXPECT_EQ(source->info().camera_distortion, Distortion{});
  EXPECT_NE(capture.text().find("cam0/sensor.yaml: distortion_model 'equidistant' is not radial-tangential"),
            std::string::npos)
      << capture.text();
  WriteText(log + "/cam0/sensor.yaml",
            "resolution: [32, 24]\nintrinsics: [30.0, 30.0, 15.5, 11.5]\ndistortion_coefficients: [0.1, .nan, 0, 0]\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("cam0/sensor.yaml: distortion_coefficients must be finite"),
            std::string::npos);
  // A coefficient no lens of this model has (the map file would refuse it).
  WriteText(log + "/cam0/sensor.yaml",
            "resolution: [32, 24]\nintrinsics: [30.0, 30.0, 15.5, 11.5]\ndistortion_coefficients: [11, 0, 0, 0]\n");
  EXPECT_NE(OpenLog(log, {}, &source).message().find("of magnitude at most 10"), std::string::npos);
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
