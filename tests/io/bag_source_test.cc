// Tests of src/io/bag_source.cc (and ros2_bag.cc): a small ROS 2 bag written here with sqlite3, whose
// numbers are known: frames timed by their header stamps (recorded 5 ms later), colour turned grey, depth in
// metres, poses turned into the camera's through a two-level /tf_static tree, IMU samples up to each frame,
// and a stereo pair calibrated from the two CameraInfo.
#ifdef PATROLMAP_TEST_ROS2
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "io/wire_writer.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/io/bag.h"
#include "patrolmap/io/readers.h"
#include "test_util.h"

namespace patrolmap::io {
namespace {

using rosmsg::Wire;
using rosmsg::WireWriter;
using testing::TempDir;

constexpr std::int64_t kSecond = 1'000'000'000;
constexpr std::int64_t kRecordDelay = 5'000'000;  // messages are recorded 5 ms after their stamp

std::uint32_t Sec(std::int64_t t) { return static_cast<std::uint32_t>(t / kSecond); }
std::uint32_t Nsec(std::int64_t t) { return static_cast<std::uint32_t>(t % kSecond); }

std::vector<std::uint8_t> Image(std::int64_t t, std::uint32_t width, std::uint32_t height, const std::string& encoding,
                                const std::vector<std::uint8_t>& pixels) {
  WireWriter w(Wire::kCdr);
  w.Header(Sec(t), Nsec(t), "cam").Put<std::uint32_t>(height).Put<std::uint32_t>(width).String(encoding);
  w.Put<std::uint8_t>(0).Put<std::uint32_t>(static_cast<std::uint32_t>(pixels.size() / height));
  w.Put<std::uint32_t>(static_cast<std::uint32_t>(pixels.size()));
  for (std::uint8_t p : pixels) w.Put(p);
  return w.bytes();
}

std::vector<std::uint8_t> CameraInfo(double baseline, double k1 = 0.0) {
  WireWriter w(Wire::kCdr);
  w.Header(0, 0, "cam").Put<std::uint32_t>(2).Put<std::uint32_t>(4).String("plumb_bob");
  w.Put<std::uint32_t>(5).Doubles({k1, 0, 0, 0.001, 0});
  w.Doubles({100, 0, 2, 0, 100, 1, 0, 0, 1}).Doubles({1, 0, 0, 0, 1, 0, 0, 0, 1});
  w.Doubles({100, 0, 2, -100 * baseline, 0, 100, 1, 0, 0, 0, 1, 0});
  w.Put<std::uint32_t>(0).Put<std::uint32_t>(0).Put<std::uint32_t>(0).Put<std::uint32_t>(0);
  w.Put<std::uint32_t>(0).Put<std::uint32_t>(0).Put<std::uint8_t>(0);
  return w.bytes();
}

Eigen::Quaterniond Turn(double degrees, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()));
}

void PutQuaternion(const Eigen::Quaterniond& q, WireWriter* w) { w->Doubles({q.x(), q.y(), q.z(), q.w()}); }

// base -> imu (A) and imu -> cam (B): the camera's frame is two levels below the root.
const Eigen::Quaterniond kBaseFromImu = Turn(90, {0, 0, 1});
const Eigen::Quaterniond kImuFromCamera = Turn(-90, {1, 0, 0});

std::vector<std::uint8_t> Transforms() {
  WireWriter w(Wire::kCdr);
  w.Put<std::uint32_t>(2);
  w.Header(0, 0, "base").String("imu").Doubles({0, 0, 0});
  PutQuaternion(kBaseFromImu, &w);
  w.Header(0, 0, "imu").String("cam").Doubles({0.1, 0, 0});
  PutQuaternion(kImuFromCamera, &w);
  return w.bytes();
}

std::vector<std::uint8_t> Odometry(std::int64_t t, const Eigen::Vector3d& position, const Eigen::Quaterniond& q) {
  WireWriter w(Wire::kCdr);
  w.Header(Sec(t), Nsec(t), "world").String("base").Doubles({position.x(), position.y(), position.z()});
  PutQuaternion(q, &w);
  for (int i = 0; i < 36; ++i) w.Put(0.0);
  w.Doubles({1, 0, 0, 0, 0, 0});
  for (int i = 0; i < 36; ++i) w.Put(0.0);
  return w.bytes();
}

// An IMU sample; with `attitude` its orientation too (else marked as none, covariance -1).
std::vector<std::uint8_t> Imu(std::int64_t t, double gyro_z, const Eigen::Quaterniond* attitude = nullptr) {
  WireWriter w(Wire::kCdr);
  w.Header(Sec(t), Nsec(t), "imu");
  if (attitude != nullptr) {
    w.Doubles({attitude->x(), attitude->y(), attitude->z(), attitude->w()}).Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0});
  } else {
    w.Doubles({0, 0, 0, 1}).Doubles({-1, 0, 0, 0, 0, 0, 0, 0, 0});
  }
  w.Doubles({0, 0, gyro_z}).Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0}).Doubles({0, 0, 9.81});
  w.Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0});
  return w.bytes();
}

std::vector<std::uint8_t> Fix(std::int64_t t, double latitude, double longitude, double altitude) {
  WireWriter w(Wire::kCdr);
  w.Header(Sec(t), Nsec(t), "gps").Put<std::int8_t>(0).Put<std::uint16_t>(1).Doubles({latitude, longitude, altitude});
  w.Doubles({0, 0, 0, 0, 0, 0, 0, 0, 0}).Put<std::uint8_t>(0);
  return w.bytes();
}

struct Message {
  std::string topic;
  std::int64_t stamp;
  std::vector<std::uint8_t> bytes;
};

class BagSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    topics_ = {{"/cam/image_raw", "sensor_msgs/msg/Image"},
               {"/cam/camera_info", "sensor_msgs/msg/CameraInfo"},
               {"/right/image_raw", "sensor_msgs/msg/Image"},
               {"/right/camera_info", "sensor_msgs/msg/CameraInfo"},
               {"/cam/depth/image_raw", "sensor_msgs/msg/Image"},
               {"/imu", "sensor_msgs/msg/Imu"},
               {"/odom", "nav_msgs/msg/Odometry"},
               {"/tf_static", "tf2_msgs/msg/TFMessage"}};
    std::vector<Message>& messages = messages_;
    messages = {{"/tf_static", kSecond / 2, Transforms()},
                {"/cam/camera_info", kSecond / 2, CameraInfo(0.0, -0.2)},
                {"/right/camera_info", kSecond / 2, CameraInfo(0.5)}};
    for (int i = 0; i < 3; ++i) {
      const std::int64_t t = kSecond + i * kSecond / 10;
      // A red pixel in a 4x2 rgb8 image; a grey right image; 1.5 m of depth.
      std::vector<std::uint8_t> rgb(4 * 2 * 3, 0);
      rgb[0] = 200;
      messages.push_back({"/cam/image_raw", t, Image(t, 4, 2, "rgb8", rgb)});
      messages.push_back({"/right/image_raw", t, Image(t, 4, 2, "mono8", std::vector<std::uint8_t>(8, 77))});
      std::vector<std::uint8_t> depth;
      for (int p = 0; p < 8; ++p) depth.insert(depth.end(), {0xDC, 0x05});  // 1500 mm, little-endian
      messages.push_back({"/cam/depth/image_raw", t, Image(t, 4, 2, "16UC1", depth)});
      for (int k = 0; k < 4; ++k) {
        const std::int64_t imu_t = t - kSecond / 10 + (k + 1) * kSecond / 40;
        messages.push_back({"/imu", imu_t, Imu(imu_t, 0.01 * (i * 4 + k))});
      }
    }
    for (int k = 0; k < 5; ++k) {
      const std::int64_t t = kSecond - kSecond / 20 + k * kSecond / 10;  // 0.95, 1.05, ... s
      messages.push_back({"/odom", t, Odometry(t, Eigen::Vector3d(k, 0, 2), Turn(10.0 * k, {0, 0, 1}))});
    }
    std::filesystem::create_directories(Folder());
    WriteBag(topics_, messages_);
  }

  void WriteBag(const std::vector<std::pair<std::string, std::string>>& topics, const std::vector<Message>& messages) {
    const std::string file = Folder() + "/flight_0.db3";
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    std::string sql =
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT, "
        "offered_qos_profiles TEXT); CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp "
        "INTEGER, data BLOB);";
    for (std::size_t i = 0; i < topics.size(); ++i) {
      sql += "INSERT INTO topics VALUES (" + std::to_string(i + 1) + ", '" + topics[i].first + "', '" +
             topics[i].second + "', 'cdr', '');";
    }
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_stmt* insert = nullptr;
    sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &insert, nullptr);
    for (const Message& m : messages) {
      int id = 0;
      for (std::size_t i = 0; i < topics.size(); ++i) id = topics[i].first == m.topic ? static_cast<int>(i) + 1 : id;
      sqlite3_bind_int(insert, 1, id);
      sqlite3_bind_int64(insert, 2, m.stamp + kRecordDelay);
      sqlite3_bind_blob(insert, 3, m.bytes.data(), static_cast<int>(m.bytes.size()), SQLITE_TRANSIENT);
      ASSERT_EQ(sqlite3_step(insert), SQLITE_DONE);
      sqlite3_reset(insert);
    }
    sqlite3_finalize(insert);
    sqlite3_close(db);
    std::ofstream(Folder() + "/metadata.yaml")
        << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
           "  relative_file_paths: [flight_0.db3]\n";
  }

  std::vector<Frame> ReadAll(const ImageFolderOptions& options, LogInfo* info) {
    std::unique_ptr<FrameSource> source;
    const Status status = OpenLog(Folder(), options, &source);
    EXPECT_TRUE(status.ok()) << status.message();
    std::vector<Frame> frames;
    if (!status.ok()) return frames;
    *info = source->info();
    Frame frame;
    while (source->Next(true, &frame).ok()) frames.push_back(frame);
    return frames;
  }

  std::string Folder() const { return dir_.path() + "/flight"; }

  std::vector<std::pair<std::string, std::string>> topics_;
  std::vector<Message> messages_;
  TempDir dir_;
};

TEST_F(BagSourceTest, FramesAreTimedByHeaderStampsAndTurnedGrey) {
  LogInfo info;
  const std::vector<Frame> frames = ReadAll({}, &info);
  ASSERT_EQ(frames.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(frames[i].timestamp_ns, kSecond + i * kSecond / 10);
  EXPECT_EQ(info.kind, "ros2-bag");
  EXPECT_EQ(info.frame_count, 3);
  EXPECT_NEAR(info.frame_rate_hz, 10.0, 1e-9);
  // Red 200 through the RGB weights (0.299): 60; through BGR's (0.114) it would be 23.
  EXPECT_EQ(frames[0].image.at<std::uint8_t>(0, 0), 60);
  ASSERT_TRUE(info.camera.has_value());
  EXPECT_DOUBLE_EQ(info.camera->fx, 100.0);
  // image_raw's lens, from its camera info's D (k1, k2, p1, p2).
  EXPECT_DOUBLE_EQ(info.camera_distortion[0], -0.2);
  EXPECT_DOUBLE_EQ(info.camera_distortion[3], 0.001);
}

TEST_F(BagSourceTest, ImuSamplesUpToEachFrame) {
  LogInfo info;
  const std::vector<Frame> frames = ReadAll({}, &info);
  ASSERT_EQ(frames.size(), 3u);
  for (const Frame& frame : frames) {
    ASSERT_EQ(frame.imu.size(), 4u);
    EXPECT_EQ(frame.imu.back().timestamp_ns, frame.timestamp_ns);  // the sample at the frame's time is its own
  }
  EXPECT_DOUBLE_EQ(frames[1].imu[0].gyro.z(), 0.04);
}

TEST_F(BagSourceTest, PosesAreTheCamerasThroughTheFrameTree) {
  LogInfo info;
  const std::vector<Frame> frames = ReadAll({}, &info);
  ASSERT_EQ(frames.size(), 3u);
  ASSERT_TRUE(info.camera_from_imu.has_value());
  EXPECT_TRUE(info.camera_from_imu->isApprox(kImuFromCamera.conjugate().toRotationMatrix(), 1e-12));
  // Frame 1 at 1.1 s lies halfway between the odometry at 1.05 s (x = 1, 10 degrees) and 1.15 s (x = 2, 20).
  ASSERT_TRUE(frames[1].pose.has_value());
  EXPECT_NEAR(frames[1].pose->position.x(), 1.5, 1e-9);
  const Eigen::Quaterniond expected = Turn(15, {0, 0, 1}) * kBaseFromImu * kImuFromCamera;
  EXPECT_NEAR(frames[1].pose->rotation.angularDistance(expected), 0.0, 1e-9);
  EXPECT_NEAR(*frames[1].speed_mps, 1.0, 1e-12);
}

TEST_F(BagSourceTest, DepthInMetresWithItsPose) {
  ImageFolderOptions options;
  LogInfo info;
  const std::vector<Frame> frames = ReadAll(options, &info);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_TRUE(info.has_depth);
  ASSERT_EQ(frames[2].depth.size(), 1u);
  const DepthSample& depth = frames[2].depth[0];
  EXPECT_FALSE(depth.stereo());
  EXPECT_FLOAT_EQ(depth.image.at<float>(1, 3), 1.5f);
  ASSERT_TRUE(depth.pose.has_value());
  EXPECT_NEAR(depth.pose->position.x(), 2.5, 1e-9);
}

TEST_F(BagSourceTest, StereoPairCalibratedFromCameraInfo) {
  ImageFolderOptions options;
  options.topics.right = "/right/image_raw";
  LogInfo info;
  const std::vector<Frame> frames = ReadAll(options, &info);
  ASSERT_EQ(frames.size(), 3u);
  ASSERT_TRUE(info.has_stereo);
  // The right camera sits 0.5 m along the left one's x axis: a left point is 0.5 m further left in it.
  EXPECT_TRUE(info.stereo->right_from_left_translation.isApprox(Eigen::Vector3d(-0.5, 0, 0), 1e-12));
  int pairs = 0;
  for (const DepthSample& sample : frames[0].depth) {
    if (!sample.stereo()) continue;
    ++pairs;
    EXPECT_EQ(sample.timestamp_ns, frames[0].timestamp_ns);
    EXPECT_EQ(sample.right_image.at<std::uint8_t>(1, 1), 77);
    EXPECT_EQ(sample.image.at<std::uint8_t>(0, 0), 60);
  }
  EXPECT_EQ(pairs, 1);
}

TEST_F(BagSourceTest, TopicsListedWithCountsAndRates) {
  std::vector<BagTopic> topics;
  ASSERT_TRUE(ListBagTopics(Folder(), &topics).ok());
  ASSERT_EQ(topics.size(), 8u);
  EXPECT_EQ(topics[0].name, "/cam/image_raw");
  EXPECT_EQ(topics[0].count, 3);
  EXPECT_NEAR(topics[0].rate_hz, 10.0, 1e-9);
  EXPECT_EQ(topics[5].count, 12);
}

TEST_F(BagSourceTest, ChosenTopicsAreChecked) {
  ImageFolderOptions options;
  options.topics.camera = "/nope";
  std::unique_ptr<FrameSource> source;
  Status status = OpenLog(Folder(), options, &source);
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_NE(status.message().find("no topic /nope"), std::string::npos) << status.message();
  options.topics.camera = "/imu";
  status = OpenLog(Folder(), options, &source);
  EXPECT_NE(status.message().find("topic /imu: type sensor_msgs/msg/Imu cannot be the camera topic"), std::string::npos)
      << status.message();
  TopicChoice choice;
  EXPECT_FALSE(ParseTopicChoice({"lidar=/x"}, &choice).ok());
  EXPECT_FALSE(ParseTopicChoice({"camera"}, &choice).ok());
  EXPECT_FALSE(ParseTopicChoice({"imu=/a", "imu=/b"}, &choice).ok());
  ASSERT_TRUE(ParseTopicChoice({"depth=/d", "right=/r"}, &choice).ok());
  EXPECT_EQ(choice.right, "/r");
}

// Without a pose topic, GPS fixes and the IMU's attitude give the poses: east, north and up about the point of
// the 0.1-degree grid nearest the first fix (at altitude 0), turned by the attitude and the camera's rotation in
// the IMU's frame.
TEST_F(BagSourceTest, PosesFromGpsAndTheImusAttitude) {
  const Eigen::Quaterniond attitude = Turn(30, {0, 0, 1});
  std::vector<Message> messages;
  for (const Message& m : messages_) {
    if (m.topic == "/odom") continue;
    messages.push_back(m.topic == "/imu" ? Message{m.topic, m.stamp, Imu(m.stamp, 0.0, &attitude)} : m);
  }
  // A fix every 0.1 s from 0.95 s, 1e-5 degrees further north each time (1.113 m).
  for (int k = 0; k < 5; ++k) {
    const std::int64_t t = kSecond - kSecond / 20 + k * kSecond / 10;
    messages.push_back({"/gps", t, Fix(t, 47.03 + 1e-5 * k, 8.04, 400.0 + k)});
  }
  std::vector<std::pair<std::string, std::string>> topics;
  for (const auto& topic : topics_) {
    if (topic.first != "/odom") topics.push_back(topic);
  }
  topics.push_back({"/gps", "sensor_msgs/msg/NavSatFix"});
  std::filesystem::remove_all(Folder());
  std::filesystem::create_directories(Folder());
  WriteBag(topics, messages);
  LogInfo info;
  const std::vector<Frame> frames = ReadAll({}, &info);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_TRUE(info.has_poses);
  EXPECT_EQ(info.pose_source, kPosesFromGps);
  // Frame 1 at 1.1 s: halfway between the fixes at 1.05 s (k = 1) and 1.15 s (k = 2).
  ASSERT_TRUE(frames[1].pose.has_value());
  const double metres_per_degree = M_PI / 180.0 * 6378137.0;  // the frame's origin: 47.0, 8.0 degrees
  EXPECT_NEAR(frames[1].pose->position.y(), (0.03 + 1.5e-5) * metres_per_degree, 1e-6);
  EXPECT_NEAR(frames[1].pose->position.x(), 0.04 * metres_per_degree * std::cos(47.0 * M_PI / 180.0), 1e-6);
  EXPECT_NEAR(frames[1].pose->position.z(), 401.5, 1e-9);
  EXPECT_NEAR(frames[1].pose->rotation.angularDistance(attitude * kImuFromCamera), 0.0, 1e-9);
}

}  // namespace
}  // namespace patrolmap::io
#endif  // PATROLMAP_TEST_ROS2
