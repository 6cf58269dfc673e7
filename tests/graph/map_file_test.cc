#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/sqlite.h"

#include "../src/graph/map_file_v12.h"
#include "graph/fixtures.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/layout.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/graph/topo_map.h"
#include "recompute_checksums.h"
#include "sample_map.h"
#include "test_util.h"

namespace patrolmap::graph {
namespace {

using testing::TwoFlights;

TEST(MapFile, RoundTripKeepsEverything) {
  testing::TempDir dir;
  const TopoMap map = TwoFlights();
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  ASSERT_EQ(loaded.node_count(), map.node_count());
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode &a = map.node(i), &b = loaded.node(i);
    EXPECT_EQ(a.flight, b.flight);
    EXPECT_EQ(a.timestamp_ns, b.timestamp_ns);
    EXPECT_EQ(a.frame_index, b.frame_index);
    EXPECT_EQ(cv::norm(a.thumbnail, b.thumbnail, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_INF), 0.0);
    ASSERT_EQ(a.points.size(), b.points.size());
    EXPECT_EQ(a.points[3], b.points[3]);
    EXPECT_EQ(a.bow.words, b.bow.words);
    EXPECT_EQ(a.bow.weights, b.bow.weights);
    EXPECT_EQ(a.gps.has_value(), b.gps.has_value());
    EXPECT_EQ(a.layout, b.layout);
  }
  EXPECT_EQ(loaded.node(2).gps->x(), 47.3572123456789);  // full precision
  const auto a = map.Edges(), b = loaded.Edges();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].a, b[i].a);
    EXPECT_EQ(a[i].b, b[i].b);
    EXPECT_EQ(a[i].data.kind, b[i].data.kind);
    EXPECT_EQ(a[i].data.inliers, b[i].data.inliers);
    EXPECT_EQ(a[i].data.bow_score, b[i].data.bow_score);
  }
  ASSERT_EQ(loaded.patrols().size(), 1u);
  const PatrolRecord& p = *loaded.Patrol("b");
  const PatrolRecord& q = *map.Patrol("b");
  EXPECT_EQ(loaded.Patrol("a"), nullptr);
  EXPECT_EQ(p.camera.fx, q.camera.fx);
  EXPECT_EQ(p.camera.height, q.camera.height);
  EXPECT_EQ(p.feature_image_width, 188);
  ASSERT_EQ(p.views.size(), 1u);
  EXPECT_EQ(p.views[0].position, q.views[0].position);
  EXPECT_EQ(p.views[0].rotation.coeffs(), q.views[0].rotation.coeffs());
  ASSERT_EQ(p.objects.size(), 1u);
  EXPECT_EQ(p.objects[0].label, "crate");
  EXPECT_EQ(p.objects[0].centroid, q.objects[0].centroid);
  EXPECT_EQ(p.objects[0].points, q.objects[0].points);
  EXPECT_EQ(p.objects[0].descriptor, q.objects[0].descriptor);
  ASSERT_EQ(p.objects[0].labels.size(), 2u);
  EXPECT_EQ(p.objects[0].labels[1].label, "barrel");
  EXPECT_EQ(p.objects[0].labels[1].count, 2);
  EXPECT_EQ(p.objects[0].last_seen_ns, 99);
  ASSERT_EQ(p.grid.voxels.size(), 3u);
  EXPECT_EQ(p.grid.voxels[2].hits, 9);
  EXPECT_EQ(p.grid.voxels[0].passes, 7);
  EXPECT_EQ(p.grid.evicted_voxels, 11);
  EXPECT_EQ(p.depth_source, "stereo");
  // Saving again gives the same bytes.
  ASSERT_TRUE(SaveMap(loaded, dir / "again.pmap").ok());
  EXPECT_EQ(testing::ReadText(dir / "m.pmap"), testing::ReadText(dir / "again.pmap"));
}

class MapFileCorruptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(SaveLegacyMap(TwoFlights(), dir_ / "m.pmap").ok());
    bytes_ = testing::ReadText(dir_ / "m.pmap");
  }
  std::string LoadBytes(const std::string& bytes) {
    std::ofstream(dir_ / "x.pmap", std::ios::binary) << bytes;
    TopoMap map;
    return LoadMap(dir_ / "x.pmap", &map).message();
  }
  testing::TempDir dir_;
  std::string bytes_;
};

TEST_F(MapFileCorruptTest, EveryCaseFailsWithAMessageNamingTheFile) {
  EXPECT_NE(LoadBytes(bytes_.substr(0, bytes_.size() - 10)).find("x.pmap: truncated map"), std::string::npos);
  EXPECT_NE(LoadBytes(bytes_.substr(0, 12)).find("truncated map (header"), std::string::npos);
  std::string flipped = bytes_;
  flipped[bytes_.size() / 2] ^= 0x10;
  EXPECT_NE(LoadBytes(flipped).find("corrupt map (checksum of section"), std::string::npos);
  EXPECT_NE(LoadBytes("%PDF-1.4 something else").find("not a patrolmap map file"), std::string::npos);
  std::string newer = bytes_;
  const std::uint32_t version = 13;
  std::memcpy(newer.data() + 8, &version, 4);
  EXPECT_NE(LoadBytes(newer).find("version 13 is not one patrolmap wrote"), std::string::npos);
  EXPECT_NE(LoadBytes(bytes_ + "xx").find("trailing bytes"), std::string::npos);
  // Voxels out of order (a grid no patrolmap wrote), with a valid checksum.
  TopoMap unsorted = TwoFlights();
  PatrolRecord record = *unsorted.Patrol("b");
  std::swap(record.grid.voxels[0], record.grid.voxels[2]);
  unsorted.SetPatrol(record);
  ASSERT_TRUE(SaveLegacyMap(unsorted, dir_ / "unsorted.pmap").ok());
  EXPECT_NE(LoadBytes(testing::ReadText(dir_ / "unsorted.pmap")).find("corrupt map (evidence grid of b)"),
            std::string::npos);
  TopoMap map;
  EXPECT_EQ(LoadMap(dir_ / "missing.pmap", &map).code(), StatusCode::kNotFound);
}

// Files with good checksums whose content no patrolmap writes: each is refused naming what is wrong.
TEST_F(MapFileCorruptTest, ImpossibleContentBehindAGoodChecksumIsRefused) {
  const auto refused = [this](const TopoMap& map, const std::string& what) {
    EXPECT_TRUE(SaveLegacyMap(map, dir_ / "bad.pmap").ok());
    const std::string message = LoadBytes(testing::ReadText(dir_ / "bad.pmap"));
    EXPECT_NE(message.find("x.pmap: corrupt map (" + what), std::string::npos) << message;
  };
  TopoMap narrow = TwoFlights();
  narrow.mutable_node(2).descriptors = cv::Mat(5, 32, CV_32FC1, cv::Scalar(0.5));
  refused(narrow, "features of node 2");
  TopoMap blank = TwoFlights();
  blank.mutable_node(1).thumbnail = cv::Mat();
  refused(blank, "thumbnail of node 1");
  TopoMap newline = TwoFlights();
  newline.mutable_node(0).flight = "a,\nb";
  refused(newline, "flight id of node 0");
  TopoMap nan_weight = TwoFlights();
  nan_weight.mutable_node(3).bow.weights[0] = std::nanf("");
  refused(nan_weight, "features of node 3");
  TopoMap negative_frame = TwoFlights();
  negative_frame.mutable_node(4).frame_index = -3;
  refused(negative_frame, "time, frame, GPS or layout of node 4");
  TopoMap far_future = TwoFlights();
  far_future.mutable_node(1).timestamp_ns = std::numeric_limits<TimestampNs>::max();
  refused(far_future, "time, frame, GPS or layout of node 1");
  TopoMap off_globe = TwoFlights();
  off_globe.mutable_node(2).gps = Eigen::Vector2d(1000.0, 8.0);
  refused(off_globe, "time, frame, GPS or layout of node 2");
  const auto patrol_refused = [&](const std::function<void(PatrolRecord*)>& damage, const std::string& what) {
    TopoMap map = TwoFlights();
    PatrolRecord record = *map.Patrol("b");
    damage(&record);
    map.SetPatrol(record);
    refused(map, what);
  };
  patrol_refused([](PatrolRecord* p) { p->views[0].rotation.coeffs().setConstant(std::nan("")); },
                 "camera or views of patrol b");
  patrol_refused([](PatrolRecord* p) { p->camera.fx = -1.0; }, "camera or views of patrol b");
  patrol_refused([](PatrolRecord* p) { p->objects[0].centroid.x() = std::nan(""); }, "object 3 of patrol b");
  patrol_refused([](PatrolRecord* p) { p->grid.voxel_size = 1e-300; }, "evidence grid of b");
  patrol_refused([](PatrolRecord* p) { p->grid.evicted_voxels = -1; }, "evidence grid of b");
  patrol_refused([](PatrolRecord* p) { p->grid.voxel_size = std::nan(""); }, "evidence grid of b");
  // Two records of one flight (a record's flight id rewritten): the second would silently replace the first.
  TopoMap twice = TwoFlights();
  for (const char* flight : {"zq7", "zq8"}) {  // flights with a record and no node
    PatrolRecord record;
    record.flight = flight;
    twice.SetPatrol(record);
  }
  ASSERT_TRUE(SaveLegacyMap(twice, dir_ / "twice.pmap").ok());
  std::string doubled = testing::ReadText(dir_ / "twice.pmap");
  const std::size_t id = doubled.find("zq8");
  ASSERT_NE(id, std::string::npos);
  doubled[id + 2] = '7';
  testing::RecomputeMapChecksums(&doubled);
  EXPECT_NE(LoadBytes(doubled).find("x.pmap: corrupt map (second patrol record of zq7"), std::string::npos)
      << LoadBytes(doubled);
  std::string version_zero = bytes_;
  const std::uint32_t zero = 0;
  std::memcpy(version_zero.data() + 8, &zero, 4);
  EXPECT_NE(LoadBytes(version_zero).find("version 0 is not one patrolmap wrote"), std::string::npos);
}

// Replaces the payload of the section whose tag starts at `tag` with `payload`, with its length and checksum.
void ReplaceSection(std::string* bytes, std::size_t tag, const std::string& payload) {
  std::uint64_t length = 0;
  std::memcpy(&length, bytes->data() + tag + 4, 8);
  const std::uint64_t new_length = payload.size(), checksum = Checksum(payload.data(), payload.size());
  std::string section = bytes->substr(tag, 4);
  section.append(reinterpret_cast<const char*>(&new_length), 8);
  section.append(reinterpret_cast<const char*>(&checksum), 8);
  bytes->replace(tag, 20 + length, section + payload);
}

// A version 1 file (before patrol records): header version 1, three sections, no PTRL.
// Rewrites the EDGE section of a saved map in the layout of format versions 1 and 2 (edge records without
// log_nfa), with its checksum.
void DowngradeEdges(std::string* bytes) {
  const std::size_t tag = bytes->find("EDGE", 16);
  ASSERT_NE(tag, std::string::npos);
  std::uint64_t length = 0;
  std::memcpy(&length, bytes->data() + tag + 4, 8);
  const std::string payload = bytes->substr(tag + 20, length);
  constexpr std::size_t kOld = 29, kNew = 37;  // a, b, kind, bow score, matched fraction, inliers (+ log_nfa)
  std::string old = payload.substr(0, 4);
  for (std::size_t at = 4; at + kNew <= payload.size(); at += kNew) old += payload.substr(at, kOld);
  ReplaceSection(bytes, tag, old);
}

// Rewrites the FEAT section of a saved map in the layout of format versions 1 to 7, where a feature was a
// 24-byte keypoint record (x, y, size, angle, response, octave) instead of its 8-byte position, with its
// checksum. `size` is written as 3, which newer readers must ignore.
void DowngradeFeatures(std::string* bytes) {
  const std::size_t tag = bytes->find("FEAT", 16);
  ASSERT_NE(tag, std::string::npos);
  std::uint64_t length = 0;
  std::memcpy(&length, bytes->data() + tag + 4, 8);
  const std::string payload = bytes->substr(tag + 20, length);
  std::size_t at = 0;
  const auto take = [&](std::size_t n) {
    std::string piece = payload.substr(at, n);
    at += n;
    return piece;
  };
  const auto count = [&] {
    std::uint32_t n = 0;
    std::memcpy(&n, payload.data() + at, 4);
    return n;
  };
  const std::uint32_t nodes = count();
  std::string old = take(4);
  for (std::uint32_t i = 0; i < nodes; ++i) {
    const std::uint32_t points = count();
    old += take(4);
    for (std::uint32_t k = 0; k < points; ++k) {
      const std::string xy = take(8);
      const float rest[3] = {3.0f, 0.0f, 0.0f};
      const std::int32_t octave = 0;
      old += xy + std::string(reinterpret_cast<const char*>(rest), 12) +
             std::string(reinterpret_cast<const char*>(&octave), 4);
    }
    std::int32_t mat[3];  // type, rows, cols
    std::memcpy(mat, payload.data() + at, 12);
    old += take(12 + static_cast<std::size_t>(mat[1]) * mat[2] * (mat[0] == CV_32F ? 4 : 1));
    old += take(4 + 4 * static_cast<std::size_t>(count()));  // BoW words
    old += take(4 + 4 * static_cast<std::size_t>(count()));  // BoW weights
  }
  ASSERT_EQ(at, payload.size());
  ReplaceSection(bytes, tag, old);
}

// The map file of `map` as an older version wrote it: the last `dropped` bytes of the one patrol record (its
// newest fields up to format 10) cut off, before format 11 also its log and digest (two empty strings: 8 bytes),
// and before format 12 its objects' site ids.
std::string OlderPatrolSection(const TopoMap& map, const std::string& path, std::uint32_t version,
                               std::uint64_t dropped) {
  EXPECT_EQ(map.Patrol("b")->source + map.Patrol("b")->source_digest, "");
  if (version < 11) dropped += 8;
  if (version < 12) dropped += 4 + 4 * map.Patrol("b")->objects.size();  // the objects' site ids
  EXPECT_TRUE(SaveLegacyMap(map, path).ok());
  std::string bytes = testing::ReadText(path);
  const std::size_t tag = bytes.find("PTRL", 16);
  EXPECT_NE(tag, std::string::npos);
  std::uint64_t length = 0;
  std::memcpy(&length, bytes.data() + tag + 4, 8);
  const std::uint64_t old_length = length - dropped;
  bytes.erase(tag + 20 + old_length, dropped);
  std::memcpy(bytes.data() + tag + 4, &old_length, 8);
  std::memcpy(bytes.data() + 8, &version, sizeof(version));
  testing::RecomputeMapChecksums(&bytes);
  if (version < 8) DowngradeFeatures(&bytes);  // keypoint records before format 8
  return bytes;
}

// A version-3 map (before the grid counted the voxels its memory budget dropped, and before the record kept
// its depth source) loads, with none dropped and no source.
TEST(MapFile, VersionThreePatrolRecordsStillLoad) {
  testing::TempDir dir;
  // The evicted-voxel count (8 bytes), the depth source ("stereo": a 4-byte length and 6 characters) and the
  // route frames (none: a 4-byte count), whether the log was timed (1 byte), the pose source (empty: its
  // 4-byte length) and the lens distortion (4 doubles).
  std::ofstream(dir / "v3.pmap", std::ios::binary) << OlderPatrolSection(TwoFlights(), dir / "m.pmap", 3, 59);
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v3.pmap", &map).ok()) << LoadMap(dir / "v3.pmap", &map).message();
  ASSERT_NE(map.Patrol("b"), nullptr);
  EXPECT_EQ(map.Patrol("b")->grid.voxels.size(), 3u);
  EXPECT_EQ(map.Patrol("b")->grid.evicted_voxels, 0);
  EXPECT_EQ(map.Patrol("b")->depth_source, "");
}

TEST(MapFile, VersionFourPatrolRecordsStillLoad) {
  testing::TempDir dir;
  std::ofstream(dir / "v4.pmap", std::ios::binary) << OlderPatrolSection(TwoFlights(), dir / "m.pmap", 4, 51);
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v4.pmap", &map).ok()) << LoadMap(dir / "v4.pmap", &map).message();
  ASSERT_NE(map.Patrol("b"), nullptr);
  EXPECT_EQ(map.Patrol("b")->grid.evicted_voxels, 11);
  EXPECT_EQ(map.Patrol("b")->depth_source, "");
}

// A patrol with two kept route frames: one with a pose and GPS, one with neither.
TopoMap WithRoute() {
  TopoMap map = TwoFlights();
  PatrolRecord record = *map.Patrol("b");
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", cv::Mat(24, 32, CV_8UC1, cv::Scalar(90)), jpeg);
  RouteFrame first;
  first.timestamp_ns = 5;
  first.frame_index = 3;
  first.pose = CameraPoseSample{5, Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5)};
  first.gps = Eigen::Vector2d(47.3572123456789, 8.5);
  first.jpeg = jpeg;
  RouteFrame second;
  second.timestamp_ns = 9;
  second.frame_index = 4;
  second.jpeg = jpeg;
  record.route = {first, second};
  map.SetPatrol(record);
  return map;
}

TEST(MapFile, RouteFramesRoundTrip) {
  testing::TempDir dir;
  const TopoMap map = WithRoute();
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  const std::vector<RouteFrame>& a = map.Patrol("b")->route;
  const std::vector<RouteFrame>& b = loaded.Patrol("b")->route;
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].timestamp_ns, 5);
  EXPECT_EQ(b[0].frame_index, 3);
  ASSERT_TRUE(b[0].pose && b[0].gps);
  EXPECT_EQ(b[0].pose->position, a[0].pose->position);
  EXPECT_EQ(b[0].pose->rotation.coeffs(), a[0].pose->rotation.coeffs());
  EXPECT_EQ(b[0].gps->x(), 47.3572123456789);
  EXPECT_FALSE(b[1].pose || b[1].gps);
  EXPECT_EQ(b[1].jpeg, a[1].jpeg);
  EXPECT_EQ(cv::imdecode(b[1].jpeg, cv::IMREAD_GRAYSCALE).cols, 32);
}

// The offset of a JPEG's baseline start-of-frame segment (0xFFC0).
std::size_t FrameHeader(const std::vector<unsigned char>& jpeg) {
  for (std::size_t i = 2; i + 1 < jpeg.size(); ++i) {
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xC0) return i;
  }
  return 0;
}

// Route frames out of time order, bytes that are not JPEG, a JPEG stating a huge image (which decoding
// would allocate), or one larger than the patrol's camera make the map corrupt, named.
TEST(MapFile, DamagedRouteFramesAreNamed) {
  testing::TempDir dir;
  for (int damage = 0; damage < 6; ++damage) {
    TopoMap map = WithRoute();
    PatrolRecord record = *map.Patrol("b");
    std::vector<unsigned char>& jpeg = record.route[0].jpeg;
    const std::size_t header = FrameHeader(jpeg);
    ASSERT_GT(header, 0u);
    if (damage == 0) record.route[1].timestamp_ns = 1;
    if (damage == 1) jpeg[0] = 'P';
    if (damage == 2) jpeg[header + 5] = jpeg[header + 6] = jpeg[header + 7] = jpeg[header + 8] = 0xEA;  // 60138 px
    if (damage == 3) jpeg.resize(header);                           // ends before its frame header
    if (damage == 4) jpeg[header + 5] = 0, jpeg[header + 6] = 200;  // 32x200, taller than the 188x120 camera
    if (damage == 5) {                                              // both 300x24, wider than the 188x120 camera
      for (RouteFrame& f : record.route) f.jpeg[header + 7] = 1, f.jpeg[header + 8] = 0x2C;
    }
    map.SetPatrol(record);
    ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
    TopoMap loaded;
    const Status status = LoadMap(dir / "m.pmap", &loaded);
    EXPECT_FALSE(status.ok());
    EXPECT_NE(status.message().find("route frames of b"), std::string::npos) << status.message();
  }
}

// A version-5 map (before the route frames) loads without them.
TEST(MapFile, VersionFivePatrolRecordsStillLoad) {
  testing::TempDir dir;
  std::ofstream(dir / "v5.pmap", std::ios::binary) << OlderPatrolSection(TwoFlights(), dir / "m.pmap", 5, 41);
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v5.pmap", &map).ok()) << LoadMap(dir / "v5.pmap", &map).message();
  EXPECT_EQ(map.Patrol("b")->depth_source, "stereo");
  EXPECT_TRUE(map.Patrol("b")->route.empty());
}

// A version-6 map (before the timed flag) loads as timed; version 7 keeps an untimed log's flag.
TEST(MapFile, VersionSixPatrolRecordsLoadAsTimed) {
  testing::TempDir dir;
  TopoMap untimed = TwoFlights();
  PatrolRecord record = *untimed.Patrol("b");
  record.timed = false;
  untimed.SetPatrol(record);
  std::ofstream(dir / "v6.pmap", std::ios::binary) << OlderPatrolSection(untimed, dir / "m.pmap", 6, 37);
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v6.pmap", &map).ok()) << LoadMap(dir / "v6.pmap", &map).message();
  EXPECT_TRUE(map.Patrol("b")->timed);
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &map).ok());
  EXPECT_FALSE(map.Patrol("b")->timed);
}

// A version-7 map (keypoint records) loads with the positions of its features, and saves as the current version.
TEST(MapFile, VersionSevenKeypointRecordsLoadAsPositions) {
  testing::TempDir dir;
  const TopoMap original = TwoFlights();
  std::ofstream(dir / "v7.pmap", std::ios::binary) << OlderPatrolSection(original, dir / "m.pmap", 7, 36);
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v7.pmap", &map).ok()) << LoadMap(dir / "v7.pmap", &map).message();
  ASSERT_EQ(map.node_count(), original.node_count());
  for (int i = 0; i < map.node_count(); ++i) {
    EXPECT_EQ(map.node(i).points, original.node(i).points);
    EXPECT_EQ(cv::norm(map.node(i).descriptors, original.node(i).descriptors, cv::NORM_INF), 0.0);
  }
  ASSERT_TRUE(SaveLegacyMap(map, dir / "again.pmap").ok());
  EXPECT_EQ(testing::ReadText(dir / "again.pmap"), testing::ReadText(dir / "m.pmap"));
}

// Where the camera poses came from is kept (format 9); a version-8 map has no source, and an unknown one is refused.
TEST(MapFile, ThePoseSourceRoundTripsAndAnUnknownOneIsRefused) {
  testing::TempDir dir;
  TopoMap map = TwoFlights();
  PatrolRecord record = *map.Patrol("b");
  record.pose_source = kPosesFromGps;
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  EXPECT_EQ(loaded.Patrol("b")->pose_source, "gps_attitude");
  std::ofstream(dir / "v8.pmap", std::ios::binary) << OlderPatrolSection(map, dir / "m.pmap", 8, 48);
  ASSERT_TRUE(LoadMap(dir / "v8.pmap", &loaded).ok()) << LoadMap(dir / "v8.pmap", &loaded).message();
  EXPECT_EQ(loaded.Patrol("b")->pose_source, "");
  record.pose_source = "gyroscope";
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("pose source of b"), std::string::npos);
}

// The lens distortion is kept (format 10); a version-9 map has none, and coefficients no lens has are refused.
TEST(MapFile, TheLensDistortionRoundTripsAndAnImpossibleOneIsRefused) {
  testing::TempDir dir;
  TopoMap map = TwoFlights();
  PatrolRecord record = *map.Patrol("b");
  record.distortion = {-0.28, 0.07, 0.0002, 0.00002};  // EuRoC's cam0
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  EXPECT_EQ(loaded.Patrol("b")->distortion, record.distortion);
  std::ofstream(dir / "v9.pmap", std::ios::binary) << OlderPatrolSection(map, dir / "m.pmap", 9, 32);
  ASSERT_TRUE(LoadMap(dir / "v9.pmap", &loaded).ok()) << LoadMap(dir / "v9.pmap", &loaded).message();
  EXPECT_EQ(loaded.Patrol("b")->distortion, Distortion{});
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), 11.0}) {
    record.distortion[1] = bad;
    map.SetPatrol(record);
    ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
    EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("camera or views of patrol b"), std::string::npos);
  }
}

// A patrol keeps its log and the log's digest (format 11); a version-10 map has neither, and a digest that is not
// 16 hex digits or a path with a control character is refused.
TEST(MapFile, ThePatrolsLogRoundTripsAndADamagedOneIsRefused) {
  testing::TempDir dir;
  TopoMap map = TwoFlights();
  std::ofstream(dir / "v10.pmap", std::ios::binary) << OlderPatrolSection(map, dir / "m.pmap", 10, 0);
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "v10.pmap", &loaded).ok()) << LoadMap(dir / "v10.pmap", &loaded).message();
  EXPECT_EQ(loaded.Patrol("b")->source, "");
  PatrolRecord record = *map.Patrol("b");
  record.source = "/data/day2/cam";
  record.source_digest = "0123456789abcdef";
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  EXPECT_EQ(loaded.Patrol("b")->source, "/data/day2/cam");
  EXPECT_EQ(loaded.Patrol("b")->source_digest, "0123456789abcdef");
  for (const auto& [source, digest] : {std::make_pair(std::string("/data/x"), std::string("not hex digits!!")),
                                       std::make_pair(std::string("/data/\n"), std::string())}) {
    record.source = source, record.source_digest = digest;
    map.SetPatrol(record);
    ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
    EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("log of b"), std::string::npos);
  }
}

// Objects keep their site ids (format 12); a version-11 map's objects have none yet, and an id below -1 or above 2^30
// is refused.
TEST(MapFile, SiteIdsRoundTripAndOlderObjectsHaveNone) {
  testing::TempDir dir;
  TopoMap map = TwoFlights();
  std::ofstream(dir / "v11.pmap", std::ios::binary) << OlderPatrolSection(map, dir / "m.pmap", 11, 0);
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "v11.pmap", &loaded).ok()) << LoadMap(dir / "v11.pmap", &loaded).message();
  ASSERT_FALSE(loaded.Patrol("b")->objects.empty());
  EXPECT_EQ(loaded.Patrol("b")->objects[0].site_id, -1);
  PatrolRecord record = *map.Patrol("b");
  record.objects[0].site_id = 17;
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  EXPECT_EQ(loaded.Patrol("b")->objects[0].site_id, 17);
  record.objects[0].site_id = -2;
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("object"), std::string::npos);
  record.objects[0].site_id = (1 << 30) + 1;  // numbering on from it could overflow
  map.SetPatrol(record);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
  EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("object"), std::string::npos);
}

// Feature positions must be finite, and descriptors one of the stored kinds (vocab/descriptors.h).
TEST(MapFile, FeaturesOfAnUnknownKindAreRefused) {
  testing::TempDir dir;
  for (int damage = 0; damage < 2; ++damage) {
    TopoMap map = TwoFlights();
    KeyFrameNode& node = map.mutable_node(1);
    if (damage == 0) node.points[0].x = std::numeric_limits<float>::quiet_NaN();
    if (damage == 1) node.descriptors = cv::Mat::zeros(static_cast<int>(node.points.size()), 100, CV_8U);
    ASSERT_TRUE(SaveMap(map, dir / "m.pmap").ok());
    TopoMap loaded;
    EXPECT_NE(LoadMap(dir / "m.pmap", &loaded).message().find("features of node 1"), std::string::npos) << damage;
  }
}

TEST(MapFile, VersionOneFilesStillLoad) {
  testing::TempDir dir;
  ASSERT_TRUE(SaveLegacyMap(TwoFlights(), dir / "m.pmap").ok());
  std::string bytes = testing::ReadText(dir / "m.pmap");
  ASSERT_NO_FATAL_FAILURE(DowngradeEdges(&bytes));
  ASSERT_NO_FATAL_FAILURE(DowngradeFeatures(&bytes));
  const std::size_t ptrl = bytes.rfind("PTRL");
  ASSERT_NE(ptrl, std::string::npos);
  bytes.resize(ptrl);
  const std::uint32_t header[2] = {1, 3};
  std::memcpy(bytes.data() + 8, header, sizeof(header));
  std::ofstream(dir / "v1.pmap", std::ios::binary) << bytes;
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "v1.pmap", &map).ok()) << LoadMap(dir / "v1.pmap", &map).message();
  EXPECT_EQ(map.node_count(), 7);
  EXPECT_EQ(map.loop_closure_count(), TwoFlights().loop_closure_count());
  EXPECT_TRUE(map.patrols().empty());
  EXPECT_EQ(map.vocabulary().fingerprint, 0u);  // unknown: version 1 records no vocabulary
}

TEST(MapFile, FailedSaveLeavesThePreviousMapIntact) {
  testing::TempDir dir;
  ASSERT_TRUE(SaveMap(TwoFlights(), dir / "m.pmap").ok());
  const std::string before = testing::ReadText(dir / "m.pmap");
  std::filesystem::create_directory(dir / "m.pmap.tmp." +
                                    std::to_string(::getpid()));  // the temporary cannot be created
  EXPECT_FALSE(SaveMap(TopoMap(), dir / "m.pmap").ok());
  EXPECT_EQ(testing::ReadText(dir / "m.pmap"), before);
}

// A big map with `nodes` nodes of 200 features each (about 50 KB a node on disk).
TopoMap BigMap(int nodes) {
  TopoMap map;
  cv::RNG rng(5);
  for (int i = 0; i < nodes; ++i) {
    KeyFrameNode node;
    node.flight = "f";
    node.thumbnail = cv::Mat(102, 160, CV_8UC1, cv::Scalar(i % 255));
    node.points.assign(200, cv::Point2f(1.0f, 2.0f));
    node.descriptors = cv::Mat(200, 128, CV_8UC1);
    rng.fill(node.descriptors, cv::RNG::UNIFORM, 0, 255);
    map.AddNode(std::move(node));
    if (i > 0) map.AddEdge(i - 1, i, EdgeData{});
  }
  return map;
}

// A process killed while it saves a large map leaves the previous map as it was.
TEST(MapFile, KillDuringSaveLeavesThePreviousMapIntact) {
  testing::TempDir dir;
  const std::string path = dir / "m.pmap";
  ASSERT_TRUE(SaveMap(TwoFlights(), path).ok());
  const std::string before = testing::ReadText(path);
  const TopoMap big = BigMap(3000);  // ~150 MB: the save takes long enough to be interrupted
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SaveMap(big, path);
    ::_exit(0);
  }
  // Kill it once its temporary file has started to grow.
  const std::string temporary = path + ".tmp." + std::to_string(child);
  for (int i = 0; i < 2000 && !(std::filesystem::exists(temporary) && std::filesystem::file_size(temporary) > 0); ++i) {
    ::usleep(1000);
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the save finished before it could be killed";
  EXPECT_EQ(testing::ReadText(path), before);
  TopoMap loaded;
  EXPECT_TRUE(LoadMap(path, &loaded).ok());
  EXPECT_EQ(loaded.node_count(), 7);
}

// How damaged copies of a map fare, written one by one to `dir`/damaged.pmap: each loads the same way twice and then
// survives a save and every export, or fails with a message that names the file. Counts the loaded and refused.
struct DamageOutcome {
  int loaded = 0, refused = 0;
};
DamageOutcome LoadEachDamaged(const std::vector<std::string>& cases, const std::string& dir) {
  const std::string damaged = dir + "/damaged.pmap";
  DamageOutcome outcome;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::ofstream(damaged, std::ios::binary | std::ios::trunc) << cases[i];
    TopoMap first, second;
    const Status a = LoadMap(damaged, &first), b = LoadMap(damaged, &second);
    EXPECT_EQ(a.ok(), b.ok()) << "case " << i;
    EXPECT_EQ(a.message(), b.message()) << "case " << i;
    if (!a.ok()) {
      EXPECT_NE(a.message().find(damaged), std::string::npos) << "case " << i << ": " << a.message();
      ++outcome.refused;
      continue;
    }
    ++outcome.loaded;
    EXPECT_EQ(ToJson(first), ToJson(second)) << "case " << i;
    for (const auto& format :
         {ToGraphML(first), ToDot(first), ToSvg(first), ToHtml(first), ToGeoJson(first), ToKml(first)}) {
      EXPECT_FALSE(format.empty()) << "case " << i;
    }
    EXPECT_TRUE(SaveMap(first, dir + "/again.pmap").ok()) << "case " << i;
  }
  return outcome;
}

// A damaged map behind good checksums (rules no paper gives): truncated at 64 offsets, and 200
// single-bit flips with the checksums recomputed (fixed seed). Each file loads the same way twice and then
// survives a save and every export, or fails with a message that names it.
TEST(MapFile, DamageBehindGoodChecksumsLoadsIdenticallyOrFailsNamingTheFile) {
  testing::TempDir dir;
  const std::string original = dir / "m.pmap";
  ASSERT_TRUE(SaveLegacyMap(TwoFlights(), original).ok());
  const std::string bytes = testing::ReadText(original);
  std::vector<std::string> cases;
  for (int i = 0; i < 64; ++i) cases.push_back(bytes.substr(0, bytes.size() * i / 64));
  std::mt19937 rng(19);
  for (int i = 0; i < 200; ++i) {
    std::string flipped = bytes;
    const std::size_t bit = std::uniform_int_distribution<std::size_t>(0, 8 * bytes.size() - 1)(rng);
    flipped[bit / 8] = static_cast<char>(flipped[bit / 8] ^ (1 << (bit % 8)));
    testing::RecomputeMapChecksums(&flipped);
    cases.push_back(flipped);
  }
  const auto [loaded, refused] = LoadEachDamaged(cases, dir.path());
  EXPECT_EQ(loaded + refused, 264);
  EXPECT_GE(refused, 64);  // every truncation (and the empty file) is refused
  EXPECT_GT(loaded, 100);  // most flips reach the parsers past the recomputed checksums (187 at seed 19)
}

// ---- The SQLite store (format 13) ----

// The bytes of `map` as format 12 writes them: equal bytes, equal maps (every record must be whole).
std::string Content(const TopoMap& map, const std::string& path) {
  EXPECT_TRUE(SaveLegacyMap(map, path).ok());
  return testing::ReadText(path);
}

// WithRoute's map with a third flight c after it: two nodes, a closure onto b, and a record with a grid.
TopoMap ThreeFlights() {
  TopoMap map = WithRoute();
  for (int i = 0; i < 2; ++i) {
    KeyFrameNode node = map.node(i);
    node.flight = "c";
    node.timestamp_ns = SecondsToNs(100.0 + i);
    map.AddNode(node);
  }
  map.AddEdge(7, 8, EdgeData{});
  map.AddEdge(8, 5, {EdgeKind::kLoopClosure, 0.3, 0.4, 40, -31.0});
  PatrolRecord c = *map.Patrol("b");
  c.flight = "c";
  c.grid.voxels = {{1, 1, 1, 3, 0}};
  c.objects[0].site_id = 4;
  map.SetPatrol(c);
  return map;
}

TEST(MapStore, AUserCanReadTheTablesWithSqlite) {
  testing::TempDir dir;
  ASSERT_TRUE(SaveMap(ThreeFlights(), dir / "m.pmap").ok());
  EXPECT_EQ(testing::ReadText(dir / "m.pmap").substr(0, 15), "SQLite format 3");
  SqliteDatabase db;
  ASSERT_TRUE(SqliteDatabase::Open(dir / "m.pmap", SqliteDatabase::Mode::kReadOnly, &db).ok());
  SqliteStatement count;
  ASSERT_TRUE(db.Prepare("SELECT count(*) FROM nodes WHERE flight = 'c'", &count).ok());
  Status status;
  ASSERT_TRUE(count.Step(&status));
  EXPECT_EQ(count.Int(0), 2);
  SqliteStatement objects;
  ASSERT_TRUE(db.Prepare("SELECT p.flight, o.label, o.site_object FROM objects o JOIN patrols p ON p.id = o.patrol "
                         "ORDER BY p.id",
                         &objects)
                  .ok());
  ASSERT_TRUE(objects.Step(&status));
  EXPECT_EQ(objects.Text(0), "b");
  EXPECT_EQ(objects.Text(1), "crate");
  ASSERT_TRUE(objects.Step(&status));
  EXPECT_EQ(objects.Text(0), "c");
  EXPECT_EQ(objects.Int(2), 4);
}

// A map of format 12 loads and saves as the database, holding the same.
TEST(MapStore, AFormatTwelveMapMigrates) {
  testing::TempDir dir;
  const TopoMap map = ThreeFlights();
  ASSERT_TRUE(SaveLegacyMap(map, dir / "old.pmap").ok());
  TopoMap old;
  ASSERT_TRUE(LoadMap(dir / "old.pmap", &old).ok());
  ASSERT_TRUE(SaveMapOnto(old, dir / "old.pmap", dir / "new.pmap").ok());
  EXPECT_EQ(testing::ReadText(dir / "new.pmap").substr(0, 15), "SQLite format 3");
  TopoMap migrated;
  ASSERT_TRUE(LoadMap(dir / "new.pmap", &migrated).ok());
  EXPECT_EQ(Content(migrated, dir / "a.bin"), Content(map, dir / "b.bin"));
}

// A patrol reads the last flight's record whole and the others without their route frames; a save onto the file it
// read keeps those, and equals a whole save of the whole map.
TEST(MapStore, APartialLoadGrownAndSavedOntoItsFileEqualsAWholeSave) {
  testing::TempDir dir;
  TopoMap whole = ThreeFlights();
  ASSERT_TRUE(SaveMap(whole, dir / "m.pmap").ok());
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &map, PatrolDetail::kLatest).ok());
  ASSERT_TRUE(map.Patrol("b")->partial);
  EXPECT_TRUE(map.Patrol("b")->route.empty());
  EXPECT_EQ(map.Patrol("b")->grid.voxels.size(), 3u);  // grids and objects are always read
  EXPECT_EQ(map.Patrol("b")->objects.size(), 1u);
  ASSERT_FALSE(map.Patrol("c")->partial);
  EXPECT_EQ(map.Patrol("c")->grid.voxels.size(), 1u);
  EXPECT_EQ(map.Patrol("c")->route.size(), 2u);
  // Grown as a patrol grows it: a node, an edge, a record, the layout and a site id renewed.
  for (TopoMap* m : {&map, &whole}) {
    KeyFrameNode node = m->node(0);
    node.flight = "d";
    node.timestamp_ns = SecondsToNs(200.0);
    m->AddNode(node);
    m->AddEdge(9, 2, {EdgeKind::kLoopClosure, 0.5, 0.6, 70, -40.0});
    PatrolRecord d = *m->Patrol("c");
    d.flight = "d";
    m->SetPatrol(d);
    m->mutable_node(3).layout = Eigen::Vector2d(7.5, 8.5);
    m->MutablePatrol("b")->objects[0].site_id = 9;
  }
  const MapRetention keep_all{1000, 10.0};
  ASSERT_TRUE(SaveMapOnto(map, dir / "m.pmap", dir / "grown.pmap", keep_all).ok());
  TopoMap grown;
  ASSERT_TRUE(LoadMap(dir / "grown.pmap", &grown).ok());
  EXPECT_EQ(Content(grown, dir / "a.bin"), Content(whole, dir / "b.bin"));
  EXPECT_EQ(grown.Patrol("b")->route.size(), 2u);  // kept in the file though never read
  // Archived as they are saved (b, the oldest of three), the two ways agree too.
  ASSERT_TRUE(SaveMapOnto(map, dir / "m.pmap", dir / "grown.pmap").ok());
  ASSERT_TRUE(SaveMap(whole, dir / "whole.pmap").ok());
  TopoMap whole_archived;
  ASSERT_TRUE(LoadMap(dir / "grown.pmap", &grown).ok());
  ASSERT_TRUE(LoadMap(dir / "whole.pmap", &whole_archived).ok());
  EXPECT_TRUE(grown.Patrol("b")->archived);
  EXPECT_EQ(Content(grown, dir / "a.bin"), Content(whole_archived, dir / "b.bin"));
}

// A map file replaced by another between a patrol's load and its save is refused, naming it; nothing is written.
TEST(MapStore, ABaseReplacedSinceItWasReadIsRefused) {
  testing::TempDir dir;
  ASSERT_TRUE(SaveMap(TwoFlights(), dir / "m.pmap").ok());
  TopoMap map;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &map, PatrolDetail::kLatest).ok());
  TopoMap other = TwoFlights();
  other.mutable_node(6).timestamp_ns += 1;  // as many nodes, another last one
  ASSERT_TRUE(SaveMap(other, dir / "m.pmap").ok());
  const Status status = SaveMapOnto(map, dir / "m.pmap", dir / "out.pmap");
  EXPECT_NE(status.message().find(dir / "m.pmap" + ": changed since this run read it"), std::string::npos)
      << status.message();
  EXPECT_FALSE(std::filesystem::exists(dir / "out.pmap"));
  ASSERT_TRUE(SaveMap(ThreeFlights(), dir / "m.pmap").ok());  // more nodes than the run read
  EXPECT_FALSE(SaveMapOnto(map, dir / "m.pmap", dir / "out.pmap").ok());
}

// Past the latest whole patrols, a patrol keeps the voxels no later patrol observed and a frame every 10 s: the
// grids of the map hold each voxel once.
TEST(MapStore, OlderPatrolsAreArchivedToWhatNoLaterPatrolSaw) {
  testing::TempDir dir;
  TopoMap map = ThreeFlights();  // records b (three voxels, frames at 5 and 9 ns) and c (voxel 1,1,1)
  KeyFrameNode node = map.node(0);
  node.flight = "d";
  node.timestamp_ns = SecondsToNs(300.0);
  map.AddNode(node);
  PatrolRecord d = *map.Patrol("c");
  d.flight = "d";
  d.grid.voxels = {{-3, 0, 1, 1, 1}, {1, 1, 1, 2, 2}};  // sees one of b's voxels again, and c's
  map.SetPatrol(d);
  ASSERT_TRUE(SaveMap(map, dir / "m.pmap", MapRetention{2, 10.0}).ok());
  TopoMap loaded;
  ASSERT_TRUE(LoadMap(dir / "m.pmap", &loaded).ok());
  const PatrolRecord& b = *loaded.Patrol("b");
  EXPECT_TRUE(b.archived);
  ASSERT_EQ(b.grid.voxels.size(), 2u);
  EXPECT_EQ(b.grid.voxels[0].y, 1);  // (-3, 1, 0)
  EXPECT_EQ(b.grid.voxels[1].x, 5);  // (5, -2, 2)
  EXPECT_EQ(b.objects.size(), 1u);
  ASSERT_EQ(b.route.size(), 1u);  // 5 and 9 ns lie within 10 s
  EXPECT_EQ(b.route[0].timestamp_ns, 5);
  EXPECT_FALSE(loaded.Patrol("c")->archived);  // c and d: the latest two
  EXPECT_EQ(loaded.Patrol("c")->grid.voxels.size(), 1u);
  // Kept whole, nothing is archived; one whole patrol archives c to nothing (d saw its one voxel).
  ASSERT_TRUE(SaveMap(map, dir / "all.pmap", MapRetention{3, 10.0}).ok());
  ASSERT_TRUE(LoadMap(dir / "all.pmap", &loaded).ok());
  EXPECT_FALSE(loaded.Patrol("b")->archived);
  EXPECT_EQ(loaded.Patrol("b")->grid.voxels.size(), 3u);
  ASSERT_TRUE(SaveMap(map, dir / "one.pmap", MapRetention{1, 0.0}).ok());
  ASSERT_TRUE(LoadMap(dir / "one.pmap", &loaded).ok());
  EXPECT_TRUE(loaded.Patrol("c")->grid.voxels.empty());
  EXPECT_EQ(loaded.Patrol("b")->route.size(), 2u);  // interval 0 keeps every frame
  std::string error;
  EXPECT_FALSE((MapRetention{0, 10.0}).IsValid(&error));
  EXPECT_EQ(error, "map.whole_patrols = 0: must be an integer in [1, 1000000]");
}

TEST(MapStore, ForeignNewerAndDamagedDatabasesAreRefusedNamingTheFile) {
  testing::TempDir dir;
  const std::string path = dir / "m.pmap";
  ASSERT_TRUE(SaveMap(ThreeFlights(), path).ok());
  const auto change = [&](const std::string& sql) {
    ASSERT_TRUE(SaveMap(ThreeFlights(), path).ok());
    SqliteDatabase db;
    ASSERT_TRUE(SqliteDatabase::Open(path, SqliteDatabase::Mode::kReadWrite, &db).ok());
    ASSERT_TRUE(db.Execute(sql).ok()) << sql;
  };
  const auto message = [&] {
    TopoMap map;
    return LoadMap(path, &map).message();
  };
  const std::pair<std::string, std::string> cases[] = {
      {"UPDATE map_info SET value = '14' WHERE key = 'version'", "map format version 14 is newer than"},
      {"UPDATE map_info SET value = 'x' WHERE key = 'version'", "corrupt map (map_info: version 'x')"},
      {"DELETE FROM map_info", "not a patrolmap map"},
      {"DROP TABLE map_info", "not a patrolmap map"},
      {"DROP TABLE edges", "no such table: edges"},
      {"UPDATE nodes SET id = 9 WHERE id = 6", "node ids"},
      {"UPDATE nodes SET thumbnail = x'00' WHERE id = 1", "thumbnail of node 1"},
      {"UPDATE nodes SET features = x'0000' WHERE id = 2", "features of node 2"},
      {"UPDATE nodes SET latitude = 91 WHERE id = 2", "GPS or layout of node 2"},
      {"UPDATE edges SET node_b = 99 WHERE id = 0", "edge 0"},
      {"UPDATE edges SET kind = 'teleport' WHERE id = 1", "edge 1"},
      {"INSERT INTO edges SELECT 100, node_a, node_b, kind, 0, 0, 0, 0 FROM edges WHERE id = 0", "repeats another"},
      {"UPDATE patrols SET views = x'00' WHERE flight = 'b'", "views of b"},
      {"UPDATE patrols SET depth_source = 'sonar' WHERE flight = 'c'", "evidence grid of c"},
      {"UPDATE patrols SET flight = 'c/d' WHERE flight = 'c'", "flight id"},
      {"UPDATE objects SET site_object = -5", "object 3 of patrol b"},
      {"UPDATE objects SET shape = x'01'", "shape of object 3"},
      {"UPDATE grids SET voxels = x'0102'", "voxels of b"},
      {"UPDATE route_frames SET jpeg = x'00'", "route frames of b"},
  };
  for (const auto& [sql, expected] : cases) {
    change(sql);
    const std::string got = message();
    EXPECT_NE(got.find(path), std::string::npos) << sql << ": " << got;
    EXPECT_NE(got.find(expected), std::string::npos) << sql << ": " << got;
  }
}

// Truncated at 32 lengths and with 300 single-byte changes (fixed seed), a database loads the same way twice and
// saves and exports, or fails naming the file.
TEST(MapStore, ADamagedDatabaseLoadsIdenticallyOrFailsNamingTheFile) {
  testing::TempDir dir;
  const std::string original = dir / "m.pmap";
  ASSERT_TRUE(SaveMap(ThreeFlights(), original).ok());
  const std::string bytes = testing::ReadText(original);
  std::vector<std::string> cases;
  for (int i = 0; i < 32; ++i) cases.push_back(bytes.substr(0, bytes.size() * i / 32));
  std::mt19937 rng(23);
  for (int i = 0; i < 300; ++i) {
    std::string changed = bytes;
    changed[std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng)] =
        static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    cases.push_back(changed);
  }
  const int refused = LoadEachDamaged(cases, dir.path()).refused;
  EXPECT_GE(refused, 31);  // every truncation but the whole file
}

}  // namespace
}  // namespace patrolmap::graph
