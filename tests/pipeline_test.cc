#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/flow/key_location_detector.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/detect.h"
#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/route.h"
#include "patrolmap/sim/village.h"
#include "test_util.h"

namespace patrolmap::pipeline {
namespace {

const std::string kDefaultConfig = std::string(PATROLMAP_SOURCE_DIR) + "/config/default.yaml";

void FlattenKeys(const YAML::Node& node, const std::string& prefix, std::set<std::string>* keys) {
  for (const auto& item : node) {
    const std::string path =
        prefix.empty() ? item.first.as<std::string>() : prefix + "." + item.first.as<std::string>();
    if (item.second.IsMap())
      FlattenKeys(item.second, path, keys);
    else
      keys->insert(path);
  }
}

// Records every configurable key with the kind of its field.
struct KeyKinds {
  std::vector<std::string> doubles, integers;
  void Field(const std::string& path, double*) { doubles.push_back(path); }
  void Field(const std::string& path, int*) { integers.push_back(path); }
  template <typename T>
  void Field(const std::string&, T*) {}
};

// The YAML file that sets the dotted `key` to `value`.
std::string YamlSetting(const std::string& key, const std::string& value) {
  std::string yaml, indent;
  std::size_t start = 0;
  for (std::size_t dot = key.find('.'); dot != std::string::npos; start = dot + 1, dot = key.find('.', start)) {
    yaml += indent + key.substr(start, dot - start) + ":\n";
    indent += "  ";
  }
  return yaml + indent + key.substr(start) + ": " + value + "\n";
}

// Every key refuses an out-of-range value with a message that names the file, the key and the value:
// NaN and infinity for every number, the largest or smallest 32-bit integer for every integer.
TEST(Config, EveryKeyRefusesAnOutOfRangeValueNamingIt) {
  testing::TempDir dir;
  KeyKinds kinds;
  Config defaults;
  VisitConfig(&defaults, &kinds);
  EXPECT_EQ(kinds.doubles.size() + kinds.integers.size(), 152u);  // every numeric key (the rest are switches)
  const auto refused = [&](const std::string& key, const std::string& value) {
    testing::WriteText(dir / "bad.yaml", YamlSetting(key, value));
    Config config;
    const Status status = LoadConfig(dir / "bad.yaml", &config);
    return !status.ok() && status.message().find("bad.yaml") != std::string::npos &&
           status.message().find(key) != std::string::npos;
  };
  for (const std::string& key : kinds.doubles) {
    EXPECT_TRUE(refused(key, ".nan")) << key << " = nan";
    EXPECT_TRUE(refused(key, ".inf") || refused(key, "-.inf")) << key << " = inf";
  }
  for (const std::string& key : kinds.integers) {
    EXPECT_TRUE(refused(key, "2147483647") || refused(key, "-2147483647")) << key;
  }
}

// A run's warnings say why nothing was found and what to change.
// The response plot labels key locations with their node ids, draws the ground truth and marks the false
// key locations; without truth it does not offer a legend entry for it.
TEST(ResponsePlot, DrawsTheTruthAndTheNodeIdsOfNodesCsv) {
  DetectionResult result;
  for (int i = 0; i < 50; ++i) {
    FlowSample sample;
    sample.timestamp_ns = SecondsToNs(0.1 * i);
    sample.raw_response = sample.smoothed_response = 0.1 + 0.01 * (i % 7);
    result.samples.push_back(sample);
  }
  result.key_locations = {{0, SecondsToNs(1.0), 10, 0.12, ExtremumKind::kPeak},
                          {1, SecondsToNs(3.0), 30, 0.11, ExtremumKind::kValley}};
  const std::string plain = ResponsePlotSvg(result, PlotTruth());
  EXPECT_EQ(plain.find("ground-truth edge"), std::string::npos);
  EXPECT_NE(plain.find("2 key locations"), std::string::npos);
  const std::size_t valley = plain.find("fill='#1d4ed8'/><text");  // the second key location's marker
  ASSERT_NE(valley, std::string::npos);
  EXPECT_EQ(plain.find("</text>", valley) - plain.find(">", plain.find("<text", valley)), 2u);  // labelled "1"
  const auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  PlotTruth truth;
  truth.times_s = {1.05, 2.0};
  truth.correct = {true, false};
  truth.node_ids = {17, 18};
  const std::string judged = ResponsePlotSvg(result, truth);
  EXPECT_NE(judged.find("ground-truth edge"), std::string::npos);
  EXPECT_EQ(count(judged, "stroke='#2a9d3a' stroke-dasharray='4 3'"), 3u);  // two edges and the legend's
  EXPECT_EQ(count(judged, "class='false'"), 1u);
  EXPECT_NE(judged.find(">17</text>"), std::string::npos);
  EXPECT_NE(judged.find(">18</text>"), std::string::npos);
}

TEST(DetectionWarnings, ShortFlatAndUntimedLogsAreExplained) {
  io::LogInfo info;
  info.path = "log";
  info.frame_rate_hz = 30.0;
  DetectionResult result;
  for (int i = 0; i < 300; ++i) {  // 50 s at 6 processed frames per second, a constant response
    FlowSample sample;
    sample.timestamp_ns = SecondsToNs(i / 6.0);
    sample.accepted_vectors = 100;
    sample.raw_response = sample.smoothed_response = 0.05;
    result.samples.push_back(sample);
  }
  const flow::KeyLocationOptions options;
  std::vector<std::string> warnings = DetectionWarnings(info, result, options);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("log: no key location: the smoothed response varies by 0, less than "
                             "flow.extrema.min_change = 0.02"),
            std::string::npos)
      << warnings[0];
  for (FlowSample& sample : result.samples) sample.accepted_vectors = 0;
  warnings = DetectionWarnings(info, result, options);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("no flow vector was accepted"), std::string::npos) << warnings[0];
  result.samples.resize(20);  // 3.2 s
  info.timed = false;
  warnings = DetectionWarnings(info, result, options);
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_NE(warnings[0].find("log: the log has no timestamps, so its frames are taken as 30 Hz"), std::string::npos);
  EXPECT_NE(warnings[1].find("log: the log lasts 3.17 s, less than twice the smoothing window"), std::string::npos)
      << warnings[1];
  EXPECT_NE(warnings[2].find("too short for the smoothing window"), std::string::npos) << warnings[2];
  result.key_locations.push_back(KeyLocation{});
  EXPECT_EQ(DetectionWarnings(info, result, options).size(), 2u);  // found one: only the two log warnings
}

TEST(Config, DefaultFileMirrorsTheOptionsStructsOneToOne) {
  Config loaded;
  loaded.flow.voting.accept = 99;  // must be overwritten by the file
  loaded.flow.voting.max_votes = 99;
  ASSERT_TRUE(LoadConfig(kDefaultConfig, &loaded).ok());
  EXPECT_EQ(ConfigToYaml(loaded), ConfigToYaml(Config{}));
  std::set<std::string> file_keys, struct_keys;
  FlattenKeys(YAML::LoadFile(kDefaultConfig), "", &file_keys);
  FlattenKeys(YAML::Load(ConfigToYaml(Config{})), "", &struct_keys);
  EXPECT_EQ(file_keys, struct_keys);
}

// Every key as a dotted path with its value as YAML writes it.
void FlattenValues(const YAML::Node& node, const std::string& prefix, std::map<std::string, std::string>* values) {
  for (const auto& item : node) {
    const std::string path =
        prefix.empty() ? item.first.as<std::string>() : prefix + "." + item.first.as<std::string>();
    if (item.second.IsMap())
      FlattenValues(item.second, path, values);
    else
      (*values)[path] = item.second.as<std::string>();
  }
}

// Two defaults are the same when they are the same number (0.3 and 0.30, 64 and 64.0) or the same word.
bool SameDefault(const std::string& documented, const std::string& value) {
  char* documented_end = nullptr;
  char* value_end = nullptr;
  const double a = std::strtod(documented.c_str(), &documented_end);
  const double b = std::strtod(value.c_str(), &value_end);
  if (!documented.empty() && *documented_end == '\0' && !value.empty() && *value_end == '\0')
    return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b));
  return documented == value;
}

// docs/configuration.md is the configuration reference: one table row per key, with the default the options
// structs give. A key added, renamed or given another default without the page fails here.
TEST(Config, TheReferencePageListsEveryKeyWithItsDefault) {
  std::ifstream page(std::string(PATROLMAP_SOURCE_DIR) + "/docs/configuration.md");
  ASSERT_TRUE(page.good());
  const std::regex row(R"(^\| `([a-z0-9_.]+)` \| ([^|]*[^ |]) \|)");
  std::map<std::string, std::string> documented;
  std::smatch match;
  for (std::string line; std::getline(page, line);) {
    if (std::regex_search(line, match, row)) {
      EXPECT_TRUE(documented.emplace(match[1], match[2]).second) << match[1] << " has two rows";
    }
  }
  std::map<std::string, std::string> defaults;
  FlattenValues(YAML::Load(ConfigToYaml(Config{})), "", &defaults);
  for (const auto& [key, value] : defaults) {
    const auto found = documented.find(key);
    if (found == documented.end()) {
      ADD_FAILURE() << key << " has no row in docs/configuration.md";
      continue;
    }
    EXPECT_TRUE(SameDefault(found->second, value))
        << key << ": the page says " << found->second << ", the default is " << value;
  }
  for (const auto& [key, value] : documented)
    EXPECT_TRUE(defaults.count(key)) << "docs/configuration.md documents " << key << ", which is no key";
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  testing::TempDir dir;
  testing::WriteText(dir / "c.yaml", "flow:\n  voting:\n    accept: 4\n    acept: 4\n");
  Config config;
  const Status status = LoadConfig(dir / "c.yaml", &config);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("c.yaml:4: flow.voting.acept: unknown key"), std::string::npos) << status.message();
}

TEST(Config, WrongTypesAndBadValuesAreReported) {
  testing::TempDir dir;
  Config config;
  testing::WriteText(dir / "a.yaml", "flow:\n  smoothing:\n    window_s: wide\n");
  Status status = LoadConfig(dir / "a.yaml", &config);
  EXPECT_NE(status.message().find("a.yaml:3: flow.smoothing.window_s: expected a number, got 'wide'"),
            std::string::npos)
      << status.message();
  testing::WriteText(dir / "b.yaml", "flow:\n  response:\n    quantity: speed\n");
  status = LoadConfig(dir / "b.yaml", &config);
  EXPECT_NE(status.message().find("expected length or line_parameter"), std::string::npos) << status.message();
  testing::WriteText(dir / "c.yaml", "flow:\n  voting:\n    accept: 1\n");  // under reject 2
  status = LoadConfig(dir / "c.yaml", &config);
  EXPECT_NE(status.message().find("c.yaml: flow.voting"), std::string::npos) << status.message();
  EXPECT_EQ(LoadConfig(dir / "missing.yaml", &config).code(), StatusCode::kNotFound);
}

TEST(Config, PartialFileKeepsOtherDefaults) {
  testing::TempDir dir;
  testing::WriteText(dir / "p.yaml", "flow:\n  smoothing:\n    mode: causal\n  extrema:\n    min_time_s: 3.5\n");
  Config config;
  ASSERT_TRUE(LoadConfig(dir / "p.yaml", &config).ok());
  EXPECT_EQ(config.flow.smoothing.mode, flow::SmoothingMode::kCausal);
  EXPECT_DOUBLE_EQ(config.flow.extrema.min_time_s, 3.5);
  EXPECT_DOUBLE_EQ(config.flow.smoothing.window_s, 5.0);
}

// Runs the detector over a simulated flight rendered in memory (only the frames it processes), with the
// flight's IMU samples and camera-IMU rotation as a log would carry them.
flow::DetectorOutput RunOnFlight(const sim::SimulatedFlight& flight, const flow::KeyLocationOptions& options) {
  const Eigen::Matrix3d camera_from_imu = sim::BodyFromCamera(flight.mount_angle).transpose();
  flow::KeyLocationDetector detector(options, {flight.camera, camera_from_imu, flight.frame_rate_hz});
  sim::Renderer renderer(&flight.scene, flight.camera, flight.lighting);
  const std::vector<ImuSample> imu = sim::ImuSamples(flight);
  std::size_t next_imu = 0;
  flow::DetectorOutput output;
  Frame frame;
  for (int i = 0; i < sim::FrameCount(flight); ++i) {
    frame.index = i;
    frame.timestamp_ns = sim::FrameTimestamp(flight, i);
    frame.imu.clear();
    while (next_imu < imu.size() && imu[next_imu].timestamp_ns <= frame.timestamp_ns)
      frame.imu.push_back(imu[next_imu++]);
    frame.speed_mps = flight.trajectory(i / flight.frame_rate_hz).velocity.norm();
    frame.image.release();
    if (detector.NeedsImage()) {
      renderer.Render(sim::CameraPoseAt(flight, flight.trajectory(i / flight.frame_rate_hz)), &frame.image, i);
    }
    detector.Process(frame, &output);
  }
  detector.Finish(&output);
  return output;
}

std::vector<KeyLocation> DetectOnFlight(const sim::SimulatedFlight& flight, const flow::KeyLocationOptions& options) {
  return RunOnFlight(flight, options).key_locations;
}

double MeanRawResponse(const flow::DetectorOutput& output) {
  double sum = 0.0;
  int count = 0;
  for (const FlowSample& sample : output.samples) {
    if (!std::isnan(sample.raw_response)) sum += sample.raw_response, ++count;
  }
  return sum / count;
}

// The street has openings (gaps) at [16, 28] and [44, 56] m; the camera flies from 8 m at 2.5 m/s, so the
// gaps are in front of the axis during [3.2, 8.0] s and [14.4, 19.2] s. The paper's detector puts a valley
// inside each opening and a peak on the facade between them; nothing else.
TEST(DetectEndToEnd, StreetWithTwoOpeningsGivesValleyPeakValley) {
  const sim::SimulatedFlight flight = sim::MakeStreetFlight(sim::StreetOptions{});
  const std::vector<KeyLocation> nodes = DetectOnFlight(flight, flow::KeyLocationOptions{});
  ASSERT_EQ(nodes.size(), 3u);
  const double expected_s[] = {5.6, 11.2, 16.8};  // opening, facade and opening centres
  const ExtremumKind kinds[] = {ExtremumKind::kValley, ExtremumKind::kPeak, ExtremumKind::kValley};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(NsToSeconds(nodes[i].timestamp_ns), expected_s[i], 1.0) << i;  // tolerance: 1 s = 2.5 m
    EXPECT_EQ(nodes[i].kind, kinds[i]) << i;
  }
  EXPECT_GT(nodes[1].response - nodes[0].response, 0.02);
}

// The causal smoother lags (window - 1) / 2 processed frames, so near the end of a log the last extremum may
// not be confirmed; a street with three openings leaves room for the first three nodes.
TEST(DetectEndToEnd, CausalSmoothingFindsTheSameNodesLater) {
  sim::StreetOptions street;
  street.walls = 4;
  const sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flow::KeyLocationOptions options;
  options.smoothing.mode = flow::SmoothingMode::kCausal;
  const std::vector<KeyLocation> nodes = DetectOnFlight(flight, options);
  ASSERT_GE(nodes.size(), 3u);
  const double lag_s = 14.5 * 5 / 30.0;  // 14.5 processed frames of 5 camera frames at 30 Hz
  const double expected_s[] = {5.6, 11.2, 16.8};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(NsToSeconds(nodes[i].timestamp_ns), expected_s[i] + lag_s, 1.0) << i;
    EXPECT_EQ(nodes[i].kind, i == 1 ? ExtremumKind::kPeak : ExtremumKind::kValley) << i;
  }
}

TEST(DetectEndToEnd, GyroDerotationRemovesTheFlowOfAYawingHover) {
  sim::StreetOptions street;
  street.static_camera = true;
  street.yaw_wobble_deg = 15.0;
  street.yaw_period_s = 4.0;
  const sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flow::KeyLocationOptions options;
  const double derotated = MeanRawResponse(RunOnFlight(flight, options));
  options.response.derotate_with_imu = false;
  const double raw = MeanRawResponse(RunOnFlight(flight, options));
  EXPECT_GT(raw, 0.1);               // rotation alone: ~0.22 image widths per second
  EXPECT_LT(derotated, 0.05 * raw);  // measured: 3 % of it remains
}

// A slow heading swing (+-15 degrees, 12 s period) passes the smoother and shifts the response; the
// gyro-derotated flow keeps all three nodes, the raw flow loses one.
TEST(DetectEndToEnd, GyroDerotationRestoresNodesUnderYawWobble) {
  sim::StreetOptions street;
  street.yaw_wobble_deg = 15.0;
  const sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flow::KeyLocationOptions options;
  const std::vector<KeyLocation> derotated = DetectOnFlight(flight, options);
  ASSERT_EQ(derotated.size(), 3u);
  const double expected_s[] = {5.6, 11.2, 16.8};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(NsToSeconds(derotated[i].timestamp_ns), expected_s[i], 1.0) << i;
  options.response.derotate_with_imu = false;
  const std::vector<KeyLocation> raw = DetectOnFlight(flight, options);
  EXPECT_NE(raw.size(), 3u);
}

// Speed swinging by +-50 % over 12 s moves the response as much as the buildings do; normalising by the
// known speed gives back exactly the three nodes of the street.
TEST(DetectEndToEnd, SpeedNormalisationRemovesNodesCausedBySpeedChanges) {
  sim::StreetOptions street;
  street.walls = 4;
  street.speed_variation = 0.5;
  const sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flow::KeyLocationOptions options;
  options.response.normalise_by_speed = true;
  options.response.reference_speed_mps = 2.5;
  const std::vector<KeyLocation> normalised = DetectOnFlight(flight, options);
  ASSERT_EQ(normalised.size(), 5u);  // valley, peak, valley, peak, valley
  for (std::size_t i = 0; i < normalised.size(); ++i) {
    EXPECT_EQ(normalised[i].kind, i % 2 == 0 ? ExtremumKind::kValley : ExtremumKind::kPeak) << i;
  }
  options.response.normalise_by_speed = false;
  EXPECT_NE(DetectOnFlight(flight, options).size(), 5u);
}

// The paper's experiment 3 as `patrolmap simulate --route l-shape --seed S` flies it (village, objects,
// lighting and sensor noise of flight 1), scored like `patrolmap eval`. Measured: seed 1: 6 nodes for 5
// expected, 2 false (a 1.5 s slit in the passage), 1 missed; seed 2: 4 nodes, 0 false, 1 missed (the paper
// reports 3 false and 1 missed for this experiment). The bounds catch a regression of detection or simulator.
eval::KeyLocationScore ScoreLShape(std::uint32_t seed) {
  sim::SimulatedFlight flight;
  sim::Village village = sim::MakeVillage({seed});
  flight.scene = std::move(village.scene);
  flight.lighting = sim::DrawLighting(seed, 1);
  flight.objects = sim::PlaceObjects(12, seed);
  sim::AddObjects(flight.objects, &flight.scene);
  sim::Route route;
  EXPECT_TRUE(sim::RoutePreset("l-shape", &route).ok());
  sim::RouteOptions options;
  options.seed = seed * 100u + 1u;
  EXPECT_TRUE(sim::FlyRoute(route, options, &flight).ok());
  std::vector<eval::TruthEdge> edges;
  for (const sim::TruthKeyLocation& truth : sim::KeyLocationTruth(flight)) {
    edges.push_back({truth.timestamp_ns, truth.frame_index, truth.opening});
  }
  return eval::ScoreKeyLocations(DetectOnFlight(flight, flow::KeyLocationOptions{}), edges);
}

TEST(DetectEndToEnd, VillageLShapeFlights) {
  int expected = 0, missed = 0, false_positives = 0;
  for (std::uint32_t seed : {1u, 2u}) {
    const eval::KeyLocationScore score = ScoreLShape(seed);
    EXPECT_LE(score.missed, 1) << seed;
    EXPECT_LE(score.false_positives, 2) << seed;
    expected += score.expected, missed += score.missed, false_positives += score.false_positives;
  }
  EXPECT_EQ(expected, 10);
  EXPECT_LE(missed, 2);
  EXPECT_LE(false_positives, 2);
}

TEST(DetectEndToEnd, HoveringCameraGivesNoKeyLocation) {
  sim::StreetOptions options;
  options.static_camera = true;
  EXPECT_TRUE(DetectOnFlight(sim::MakeStreetFlight(options), flow::KeyLocationOptions{}).empty());
}

TEST(DetectEndToEnd, LogOnDiskToOutputFiles) {
  testing::TempDir dir;
  sim::StreetOptions street;
  street.speed_mps = 5.0;
  ASSERT_TRUE(sim::WriteEurocLog(sim::MakeStreetFlight(street), dir / "log").ok());
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(dir / "log", {}, &source).ok());
  DetectionResult result;
  ASSERT_TRUE(RunDetection(source.get(), flow::KeyLocationOptions{}, &result).ok());
  EXPECT_TRUE(result.derotated);
  EXPECT_EQ(result.frames_read, source->info().frame_count);
  EXPECT_EQ(static_cast<std::int64_t>(result.samples.size()), (result.frames_read + 4) / 5);
  ASSERT_TRUE(WriteDetectionOutputs(result, dir / "out", PlotTruth{{1.0, 2.0}, {}, {}}).ok());
  const std::string nodes = testing::ReadText(dir / "out/key_locations.csv");
  EXPECT_EQ(nodes.substr(0, nodes.find('\n')), "node,timestamp_ns,frame_index,response,kind");
  EXPECT_EQ(static_cast<std::size_t>(std::count(nodes.begin(), nodes.end(), '\n')), result.key_locations.size() + 1);
  const std::string response = testing::ReadText(dir / "out/response.csv");
  EXPECT_EQ(static_cast<std::size_t>(std::count(response.begin(), response.end(), '\n')), result.samples.size() + 1);
  const std::string svg = testing::ReadText(dir / "out/response.svg");
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

}  // namespace
}  // namespace patrolmap::pipeline

#include "patrolmap/change/grid_alignment.h"
#include "patrolmap/eval/loop_closure_score.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/pipeline/change_events.h"
#include "patrolmap/pipeline/flight_pass.h"
#include "patrolmap/pipeline/map.h"
#include "patrolmap/pipeline/patrol_recorder.h"
#include "patrolmap/pipeline/route_strip.h"

namespace patrolmap::pipeline {
namespace {

// The same street flown twice under different lighting (logs street-1 and street-2 in `dir`), and a small
// vocabulary from the first flight's frames.
void TwoStreetFlights(const std::filesystem::path& dir, const Config& config, vocab::Vocabulary* vocabulary) {
  std::vector<cv::Mat> training;
  for (int flight = 1; flight <= 2; ++flight) {
    sim::StreetOptions street;
    street.walls = 2;
    street.speed_mps = 5.0;
    sim::SimulatedFlight simulated = sim::MakeStreetFlight(street);
    simulated.flight_id = "street-" + std::to_string(flight);
    simulated.lighting = sim::DrawLighting(7, flight);
    ASSERT_TRUE(sim::WriteEurocLog(simulated, dir / simulated.flight_id).ok());
  }
  // A small vocabulary from the first flight's frames.
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(dir / "street-1", {}, &source).ok());
  Frame frame;
  while (source->Next(true, &frame).ok()) {
    if (frame.index % 10 != 0) continue;
    cv::Mat small, descriptors;
    std::vector<cv::Point2f> points;
    cv::resize(frame.image, small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    place::DescribeFeatures(small, config.place, &points, &descriptors);
    training.push_back(descriptors);
  }
  vocab::VocabularyOptions vocabulary_options;
  vocabulary_options.branching = 8;
  vocabulary_options.depth = 3;
  ASSERT_TRUE(vocab::Vocabulary::Train(training, vocabulary_options, vocabulary).ok());
}

// The patrol recorder turns a frame's samples into work: each depth image for the grid, and the detections
// with the depth image of the frame's own time only (none when the depth camera missed that instant).
// The route strip keeps a frame a second and every key frame; past its memory budget every other interval
// frame goes and the interval doubles, key frames stay, and the frames come out in time order.
TEST(RouteStrip, ThinsIntervalFramesPastItsBudgetAndKeepsKeyFrames) {
  change::RouteFrameOptions options;
  options.max_width = 32;
  cv::Mat noise(48, 64, CV_8UC1);
  cv::randu(noise, 0, 255);  // JPEG cannot shrink noise: every frame takes about the same bytes
  std::vector<unsigned char> one;
  cv::imencode(".jpg", noise(cv::Rect(0, 0, 32, 24)), one, {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
  options.memory_mb = 10.5 * static_cast<double>(one.size()) / (1024.0 * 1024.0);  // about 10 frames
  RouteStrip strip(options);
  EXPECT_TRUE(strip.Due(0));
  EXPECT_FALSE(strip.Due(SecondsToNs(0.5)));
  EXPECT_TRUE(strip.Due(SecondsToNs(1.0)));
  cv::Mat scaled;
  strip.Scale(noise, &scaled);
  EXPECT_EQ(scaled.size(), cv::Size(32, 24));
  for (int i = 0; i < 16; ++i) {
    RouteFrame frame;
    frame.timestamp_ns = SecondsToNs(i);
    frame.frame_index = i;
    strip.Add(frame, noise(cv::Rect(0, 0, 32, 24)), false);
  }
  RouteFrame key;
  key.timestamp_ns = SecondsToNs(4.5);
  key.frame_index = 99;
  strip.Add(key, noise(cv::Rect(0, 0, 32, 24)), true);
  EXPECT_EQ(strip.thinnings(), 1);
  const std::vector<RouteFrame> frames = strip.Take();
  std::vector<std::int64_t> indices;
  for (const RouteFrame& f : frames) indices.push_back(f.frame_index);
  EXPECT_EQ(indices, (std::vector<std::int64_t>{0, 2, 4, 99, 6, 8, 10, 12, 14}));
}

// A camera whose rate is no divisor of the interval (KITTI's 10.36 Hz) still gives a route frame a second: the
// interval is a schedule, not a wait after the frame kept (which gave one every 1.036 s, 97 in 100 s).
TEST(RouteStrip, KeepsAFrameAnIntervalWhateverTheCameraRate) {
  RouteStrip strip(change::RouteFrameOptions{});
  int due = 0;
  for (int i = 0; i * 0.1036 < 100.0; ++i) due += strip.Due(SecondsToNs(i * 0.1036));
  EXPECT_EQ(due, 100);
}

// The lens goes into the record, which the map keeps, whether or not the log can feed objects and geometry.
TEST(PatrolRecorder, TheRecordKeepsTheLogsLensDistortion) {
  io::LogInfo info;
  info.camera = CameraIntrinsics{40.0, 40.0, 31.5, 23.5, 64, 48};
  info.camera_distortion = {-0.28, 0.07, 0.0002, 0.00002};
  for (const bool poses : {false, true}) {
    info.has_poses = info.has_depth = poses;
    PatrolRecorder recorder(Config{}, info);
    EXPECT_EQ(recorder.active(), poses);
    PatrolRecord record;
    PatrolRecordStats stats;
    recorder.Finish(&record, &stats);
    EXPECT_EQ(record.distortion, info.camera_distortion);
  }
  EXPECT_EQ(CameraOnlyRecord(info).distortion, info.camera_distortion);
}

TEST(PatrolRecorder, AnObjectFrameTakesOnlyTheDepthImageOfItsOwnTime) {
  io::LogInfo info;
  info.camera = CameraIntrinsics{40.0, 40.0, 31.5, 23.5, 64, 48};
  info.has_poses = info.has_detections = info.has_depth = true;
  PatrolRecorder recorder(Config{}, info);
  ASSERT_TRUE(recorder.active());
  Frame frame;
  frame.timestamp_ns = 1000;
  frame.image = cv::Mat(48, 64, CV_8UC1, cv::Scalar(0));
  frame.pose = CameraPoseSample{1000, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};
  frame.detections.resize(2);
  frame.depth = {{990, "early.png", "", {}, {}, frame.pose}, {1000, "own.png", "", {}, {}, frame.pose}};
  std::vector<ChangeWork> work;
  recorder.Collect(frame, &work);
  ASSERT_EQ(work.size(), 4u);  // the first frame for the route strip, two depth images for the grid, the detections
  EXPECT_EQ(work[0].kind, ChangeWork::Kind::kRoute);
  work.erase(work.begin());
  EXPECT_EQ(work[0].kind, ChangeWork::Kind::kGrid);
  EXPECT_EQ(work[2].kind, ChangeWork::Kind::kObjects);
  EXPECT_EQ(work[2].detections.size(), 2u);
  EXPECT_EQ(work[2].depth_path, "own.png");
  frame.timestamp_ns = 2000;
  frame.depth = {{1990, "early.png", "", {}, {}, frame.pose}, {2010, "late.png", "", {}, {}, frame.pose}};
  work.clear();
  recorder.Collect(frame, &work);
  ASSERT_EQ(work.size(), 3u);
  EXPECT_EQ(work[2].depth_path, "");
}

// Records the first `max_frames` frames of the log at `path` with `config`, the frame thread's work applied at once.
PatrolRecordStats RecordLog(const std::string& path, const Config& config, int max_frames, PatrolRecord* record) {
  std::unique_ptr<io::FrameSource> source;
  EXPECT_TRUE(io::OpenLog(path, {}, &source).ok());
  PatrolRecorder recorder(config, source->info());
  Frame frame;
  std::vector<ChangeWork> work;
  for (int i = 0; i < max_frames && source->Next(false, &frame).ok(); ++i) {
    work.clear();
    recorder.Collect(frame, &work);
    for (const ChangeWork& step : work) recorder.Apply(step);
  }
  PatrolRecordStats stats;
  recorder.Finish(record, &stats);
  return stats;
}

// Onboard events: an object the prior patrol did not have is announced once two checks in a row find it, as
// one whole JSON line.
// A simulated street flown with a depth camera and a stereo pair 0.5 m wide (logged as EuRoC cam0 + cam1
// with their sensor.yaml): the reader pairs the images, and the depth stage, from the calibration it read,
// gives the depth of depth0/ (the renderer's exact depth) wherever it finds one.
class StereoStreet : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    sim::StreetOptions street;
    street.walls = 2;
    street.speed_mps = 10.0;  // a short log: each test's process renders it again
    sim::LogOptions options;
    options.depth = true;
    options.stereo_baseline_m = 0.5;
    ASSERT_TRUE(sim::WriteEurocLog(sim::MakeStreetFlight(street), *dir_ / "log", options).ok());
  }
  static void TearDownTestSuite() { delete dir_; }
  static testing::TempDir* dir_;
};
testing::TempDir* StereoStreet::dir_ = nullptr;

TEST_F(StereoStreet, StereoDepthAgreesWithTheDepthCamera) {
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(*dir_ / "log", {}, &source).ok());
  const io::LogInfo& info = source->info();
  ASSERT_TRUE(info.has_stereo && info.has_depth);
  EXPECT_NEAR(info.stereo->right_from_left_translation.norm(), 0.5, 1e-9);
  std::unique_ptr<depth::StereoDepth> stereo;
  ASSERT_TRUE(depth::StereoDepth::Create(*info.stereo, depth::StereoOptions(), &stereo).ok());
  Frame frame;
  int truth = 0, found = 0, close = 0;
  std::vector<double> errors;
  while (source->Next(false, &frame).ok()) {
    if (frame.index % 40 != 0) continue;
    const DepthSample* images = nullptr;
    const DepthSample* pair = nullptr;
    for (const DepthSample& sample : frame.depth) (sample.stereo() ? pair : images) = &sample;
    ASSERT_TRUE(images != nullptr && pair != nullptr);
    EXPECT_EQ(pair->timestamp_ns, images->timestamp_ns);
    cv::Mat exact, matched;
    ASSERT_TRUE(io::ReadDepthImage(images->path, &exact).ok());
    ASSERT_TRUE(stereo
                    ->Compute(cv::imread(pair->path, cv::IMREAD_GRAYSCALE),
                              cv::imread(pair->right_path, cv::IMREAD_GRAYSCALE), &matched)
                    .ok());
    for (int y = 0; y < exact.rows; y += 4) {
      for (int x = 0; x < exact.cols; x += 4) {
        const float z = exact.at<float>(y, x), m = matched.at<float>(y, x);
        if (z <= 0 || z > 15) continue;
        ++truth;
        if (m <= 0) continue;
        ++found;
        close += std::abs(m - z) <= stereo->RangeSigma(z) * 4 + 0.05;
      }
    }
  }
  ASSERT_GT(truth, 1000);
  std::printf("stereo street: %d of %d depth pixels matched, %d of them within 4 range errors\n", found, truth, close);
  EXPECT_GT(found, 0.7 * truth);
  EXPECT_GT(close, 0.95 * found);
}

TEST_F(StereoStreet, TheRecordTakesTheDepthTheConfigurationChooses) {
  const auto source_of = [](depth::DepthSource choice) {
    std::unique_ptr<io::FrameSource> source;
    EXPECT_TRUE(io::OpenLog(*dir_ / "log", {}, &source).ok());
    Config config;
    config.depth.source = choice;
    PatrolRecorder recorder(config, source->info());
    PatrolRecord record;
    PatrolRecordStats stats;
    recorder.Finish(&record, &stats);
    EXPECT_EQ(record.pose_source, kPosesFromStateEstimate);
    return record.depth_source;
  };
  EXPECT_EQ(source_of(depth::DepthSource::kAuto), "images");
  EXPECT_EQ(source_of(depth::DepthSource::kImages), "images");
  EXPECT_EQ(source_of(depth::DepthSource::kStereo), "stereo");
  EXPECT_EQ(source_of(depth::DepthSource::kNone), "");
}

TEST_F(StereoStreet, TheGridWorksOnlyOnTheChosenDepth) {
  for (const depth::DepthSource choice : {depth::DepthSource::kImages, depth::DepthSource::kStereo}) {
    std::unique_ptr<io::FrameSource> source;
    ASSERT_TRUE(io::OpenLog(*dir_ / "log", {}, &source).ok());
    Config config;
    config.depth.source = choice;
    PatrolRecorder recorder(config, source->info());
    Frame frame;
    std::vector<ChangeWork> work;
    for (int i = 0; i < 30 && source->Next(false, &frame).ok(); ++i) recorder.Collect(frame, &work);
    ASSERT_FALSE(work.empty());
    for (const ChangeWork& step : work) {
      EXPECT_EQ(step.right_path.empty(), choice == depth::DepthSource::kImages) << step.depth_path;
    }
  }
}

// Depth images go to the grid at change.grid.rate_hz; stereo pairs, which cost far more, are matched at
// depth.stereo.rate_hz, or at the grid's rate when that is lower. One second of the 30 Hz log.
TEST_F(StereoStreet, EachDepthSourceIsTakenAtItsOwnRate) {
  const auto grid_frames = [](depth::DepthSource choice, double grid_hz, double stereo_hz) {
    Config config;
    config.depth.source = choice;
    config.depth.stereo.fuse_frames = 0;
    config.change.grid.rate_hz = grid_hz;
    config.depth.stereo.rate_hz = stereo_hz;
    PatrolRecord record;
    const PatrolRecordStats stats = RecordLog(*dir_ / "log", config, 30, &record);
    return std::make_pair(stats.depth_frames, stats.stereo_pairs);
  };
  EXPECT_EQ(grid_frames(depth::DepthSource::kImages, 15.0, 5.0), std::make_pair(15, 0));
  EXPECT_EQ(grid_frames(depth::DepthSource::kImages, 10.0, 30.0), std::make_pair(10, 0));
  EXPECT_EQ(grid_frames(depth::DepthSource::kStereo, 15.0, 5.0), std::make_pair(5, 5));
  EXPECT_EQ(grid_frames(depth::DepthSource::kStereo, 3.0, 10.0), std::make_pair(3, 3));
}

// A frame both the grid and the object map take (detections at a grid frame's time) is matched once, and both
// get its depth.
TEST_F(StereoStreet, AFrameTheGridAndTheObjectMapBothTakeIsMatchedOnce) {
  std::unique_ptr<io::FrameSource> source;
  ASSERT_TRUE(io::OpenLog(*dir_ / "log", {}, &source).ok());
  Config config;
  config.depth.source = depth::DepthSource::kStereo;
  PatrolRecorder recorder(config, source->info());
  Frame frame;
  std::vector<ChangeWork> work;
  ASSERT_TRUE(source->Next(false, &frame).ok());
  recorder.Collect(frame, &work);
  const auto grid =
      std::find_if(work.begin(), work.end(), [](const ChangeWork& w) { return w.kind == ChangeWork::Kind::kGrid; });
  ASSERT_NE(grid, work.end());
  ASSERT_TRUE(grid->pose.has_value());
  ChangeWork objects = *grid;
  objects.kind = ChangeWork::Kind::kObjects;
  ChangeWork later = *grid;  // the next frame's pair: matched again
  later.timestamp_ns += 1;
  later.kind = ChangeWork::Kind::kObjects;
  recorder.Apply(*grid);
  recorder.Apply(objects);
  recorder.Apply(later);
  PatrolRecord record;
  PatrolRecordStats stats;
  recorder.Finish(&record, &stats);
  EXPECT_EQ(stats.depth_frames, 1);
  EXPECT_EQ(stats.skipped_depth_frames, 0);
  EXPECT_EQ(stats.stereo_pairs, 2);
  EXPECT_GT(record.grid.voxels.size(), 100u);
}

// The evidence grid of the whole log at `path`, from the depth `choice` gives, with `fuse_frames` (stereo only).
EvidenceGridData GridOfLog(const std::string& path, depth::DepthSource choice, int fuse_frames) {
  Config config;
  config.depth.source = choice;
  config.depth.stereo.fuse_frames = fuse_frames;
  PatrolRecord record;
  RecordLog(path, config, std::numeric_limits<int>::max(), &record);
  return record.grid;
}

// A street flown sideways past facades 5 m away, with a background 16 m away: beyond the 15.1 m where one pair
// 0.5 m wide (0.5 px of noise at 458 px) marks surfaces, within the 18.6 m where five frames fused with the
// defaults do (a third of the variance shared). Occupied voxels count as on a surface when the depth camera's grid
// has one within a voxel.
TEST(FusedStereo, MarksTheBackgroundAndCleansNearReturns) {
  testing::TempDir dir;
  sim::StreetOptions street;
  street.walls = 2;
  street.speed_mps = 5.0;
  street.far_depth_m = 16.0;
  sim::LogOptions options;
  options.depth = true;
  options.stereo_baseline_m = 0.5;
  ASSERT_TRUE(sim::WriteEurocLog(sim::MakeStreetFlight(street), dir / "log", options).ok());
  const EvidenceGridData exact = GridOfLog(dir / "log", depth::DepthSource::kImages, 0);
  struct Count {
    int near_on = 0, near_off = 0, far_on = 0, far_off = 0;  // nearer than 14 m from the route, or farther
  };
  const auto score = [&exact](const EvidenceGridData& grid) {
    Count count;
    for (const VoxelEvidence& v : grid.voxels) {
      if (!change::IsOccupied(&v)) continue;
      bool on = false;
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            on |= change::IsOccupied(change::FindVoxel(exact, Eigen::Vector3i(v.x + dx, v.y + dy, v.z + dz)));
          }
        }
      }
      const bool far = v.y * exact.voxel_size > 14.0;
      ++(far ? (on ? count.far_on : count.far_off) : (on ? count.near_on : count.near_off));
    }
    return count;
  };
  const Count single = score(GridOfLog(dir / "log", depth::DepthSource::kStereo, 0));
  const Count fused = score(GridOfLog(dir / "log", depth::DepthSource::kStereo, 4));
  std::printf(
      "occupied voxels within 14 m on a surface / off, beyond: one pair %d / %d, %d / %d; fused %d / %d, %d / %d\n",
      single.near_on, single.near_off, single.far_on, single.far_off, fused.near_on, fused.near_off, fused.far_on,
      fused.far_off);
  EXPECT_EQ(single.far_on + single.far_off, 0);  // one pair marks nothing there
  EXPECT_GT(fused.far_on, 2000);
  EXPECT_LT(fused.far_off, 0.25 * fused.far_on);  // most of the background where it stands
  EXPECT_GT(fused.near_on, 0.98 * single.near_on);
  EXPECT_LT(fused.near_off, 0.95 * single.near_off);  // averaged returns stray less
}

// Checks every second of flight, nothing left out as unsettled: the ChangeMonitor tests' options.
ChangeEventOptions ChecksEverySecond() {
  ChangeEventOptions options;
  options.interval_s = 1.0;
  options.settle_s = 0.0;
  return options;
}

// Frame `i` of a 64x48 camera standing at the origin, 0.1 s apart.
Frame StillFrame(int i) {
  Frame frame;
  frame.timestamp_ns = SecondsToNs(0.1 * i);
  frame.image = cv::Mat(48, 64, CV_8UC1, cv::Scalar(100));
  frame.pose = CameraPoseSample{frame.timestamp_ns, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};
  frame.poses = {*frame.pose};
  return frame;
}

// A map whose flight "before" holds `grid` (from depth0/ images), as a ChangeMonitor's prior.
graph::TopoMap MapOfAGrid(const CameraIntrinsics& camera, const change::EvidenceGrid& grid) {
  graph::TopoMap map;
  PatrolRecord before;
  before.flight = "before";
  before.camera = camera;
  before.grid = grid.ToData();
  before.depth_source = "images";
  map.SetPatrol(before);
  return map;
}

// The events a ChangeMonitor against flight "before" of `prior` sends while a camera standing at the origin sees
// `depth` every 0.1 s for 2.5 s (checks as `options` say).
std::string EventsOfAStillCamera(const graph::TopoMap& prior, const CameraIntrinsics& camera, const cv::Mat& depth,
                                 const Config& config, const ChangeEventOptions& options) {
  testing::TempDir dir;
  std::unique_ptr<ChangeMonitor> monitor;
  EXPECT_TRUE(ChangeMonitor::Open(&prior, "before", config, options, dir / "events.jsonl", &monitor).ok());
  io::LogInfo info;
  info.camera = camera;
  info.has_poses = info.has_depth = true;
  PatrolRecorder recorder(config, info);
  std::vector<ChangeWork> work;
  for (int i = 0; i <= 25; ++i) {
    Frame frame = StillFrame(i);
    DepthSample sample;
    sample.timestamp_ns = frame.timestamp_ns;
    sample.image = depth;
    sample.pose = frame.pose;
    frame.depth = {sample};
    work.clear();
    recorder.Collect(frame, &work);
    for (const ChangeWork& step : work) {
      recorder.Apply(step);
      monitor->OnChangeStep(step.timestamp_ns, recorder);
    }
  }
  return testing::ReadText(dir / "events.jsonl");
}

TEST(ChangeMonitor, AnOptionOutOfRangeIsRefusedNamingItsFlag) {
  ChangeEventOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.min_observations = 0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("--events-min-observations"), std::string::npos) << error;
  testing::TempDir dir;
  graph::TopoMap prior;
  std::unique_ptr<ChangeMonitor> monitor;
  const Status status = ChangeMonitor::Open(&prior, "before", Config(), options, dir / "events.jsonl", &monitor);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("--events-min-observations"), std::string::npos) << status.message();
}

TEST(ChangeMonitor, ANewObjectIsSentWhenTwoChecksInARowFindIt) {
  testing::TempDir dir;
  const CameraIntrinsics camera{40.0, 40.0, 31.5, 23.5, 64, 48};
  graph::TopoMap prior;
  PatrolRecord before;
  before.flight = "before";
  before.camera = camera;
  before.has_objects = true;  // ... and none seen
  prior.SetPatrol(before);
  Config config;
  const ChangeEventOptions options = ChecksEverySecond();
  std::unique_ptr<ChangeMonitor> monitor;
  ASSERT_TRUE(ChangeMonitor::Open(&prior, "before", config, options, dir / "events.jsonl", &monitor).ok());
  io::LogInfo info;
  info.camera = camera;
  info.has_poses = info.has_detections = true;
  PatrolRecorder recorder(config, info);
  std::vector<ChangeWork> work;
  int events_after_first_check = -1;
  for (int i = 0; i <= 25; ++i) {  // frames every 0.1 s; checks at 1 s and 2 s
    Frame frame = StillFrame(i);
    if (i < 5) {  // a crate 5 m ahead
      ObjectObservation crate{frame.timestamp_ns, "crate", 0.9, cv::Rect2d(22, 14, 20, 20), Eigen::Vector3d(0, 0, 5)};
      frame.detections = {crate};
    }
    work.clear();
    recorder.Collect(frame, &work);
    if (work.empty()) {  // a frame without detections still advances the checks
      ChangeWork step;
      step.kind = ChangeWork::Kind::kViews;
      step.timestamp_ns = frame.timestamp_ns;
      work.push_back(step);
    }
    for (const ChangeWork& step : work) {
      recorder.Apply(step);
      monitor->OnChangeStep(step.timestamp_ns, recorder);
    }
    if (i == 15) events_after_first_check = monitor->events();
  }
  EXPECT_EQ(events_after_first_check, 0);
  EXPECT_EQ(monitor->events(), 1);
  const std::string text = testing::ReadText(dir / "events.jsonl");
  EXPECT_NE(text.find("\"type\":\"object_new\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"id\":\"object-p-1-c0\""), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');
}

// A wall 5 m ahead in both flights and, in the second, a box 4 m ahead in front of it. Every check while flying
// compares the grid so far; one that asks more rays per voxel than any voxel has compares nothing and sends no
// geometry event, while the default floor sends the box.
TEST(ChangeMonitor, ChecksWhileFlyingCompareOnlyVoxelsSeenByTheirRays) {
  const CameraIntrinsics camera{40.0, 40.0, 31.5, 23.5, 64, 48};
  const CameraPoseSample pose{0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};
  const cv::Mat wall(48, 64, CV_32FC1, cv::Scalar(5.0f));
  cv::Mat with_box = wall.clone();
  with_box(cv::Rect(40, 16, 16, 16)).setTo(4.0f);
  Config config;
  change::EvidenceGrid prior_grid(config.change.grid);
  for (int i = 0; i < 25; ++i) prior_grid.Integrate(wall, camera, pose);
  const graph::TopoMap prior = MapOfAGrid(camera, prior_grid);
  const auto events_with = [&](int min_observations) {
    ChangeEventOptions options = ChecksEverySecond();  // checks at 1 s and 2 s
    options.min_observations = min_observations;
    return EventsOfAStillCamera(prior, camera, with_box, config, options);
  };
  const std::string floor_of_three = events_with(3);
  EXPECT_NE(floor_of_three.find("\"type\":\"geometry\""), std::string::npos) << floor_of_three;
  EXPECT_EQ(events_with(65535), "");
}

// A wall 8 m ahead with a pillar standing out of it (0.4 m deep, 1.4 m wide, 2 m tall). The first flight saw it from
// three places along the wall with its poses 1 m (five voxels) off to the side; the second from the middle one, with
// right poses. Only the pillar tells the shift: moving the second flight by it overlaps about 15 % more voxels than
// leaving it, less than min_gain, while about a tenth of the surfaces differ. Such a check holds its changes back,
// since what differs may be that shift: nothing is sent. With the alignment off the pillar is sent as changed.
TEST(ChangeMonitor, NothingIsSentWhileAShiftFitsBetterButNotYetByMinGain) {
  const CameraIntrinsics camera{400.0, 400.0, 159.5, 119.5, 320, 240};
  const auto seen_from = [&](double x) {  // depth from a camera at (x, 0, 0) looking along +z
    cv::Mat depth(240, 320, CV_32FC1, cv::Scalar(8.0f));
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        const double px = x + 7.6 * (u - camera.cx) / camera.fx, py = 7.6 * (v - camera.cy) / camera.fy;
        if (px >= -0.1 && px < 1.3 && py >= -1.1 && py < 0.9) depth.at<float>(v, u) = 7.6f;  // voxels 0-6, -5-4
      }
    }
    return depth;
  };
  const cv::Mat scene = seen_from(0.0);
  Config config;
  change::EvidenceGrid prior_grid(config.change.grid);
  for (const double x : {-2.0, 0.0, 2.0}) {
    const cv::Mat view = seen_from(x);
    const CameraPoseSample off{0, Eigen::Vector3d(x + 1.0, 0.0, 0.0), Eigen::Quaterniond::Identity()};
    for (int i = 0; i < 10; ++i) prior_grid.Integrate(view, camera, off);
  }
  const graph::TopoMap prior = MapOfAGrid(camera, prior_grid);
  const auto events_with = [&](const Config& config) {
    return EventsOfAStillCamera(prior, camera, scene, config, ChecksEverySecond());
  };
  change::EvidenceGrid current_grid(config.change.grid);  // the second flight's, as a check at its end sees it
  for (int i = 0; i < 25; ++i) current_grid.Integrate(scene, camera, CameraPoseSample{});
  const change::GridShift search =
      change::FindGridShift(prior.Patrol("before")->grid, current_grid, config.change.alignment);
  EXPECT_TRUE(search.Undecided()) << search.best_overlap << " vs " << search.overlap_unshifted;
  EXPECT_EQ(search.best, Eigen::Vector3i(5, 0, 0));
  EXPECT_EQ(events_with(config), "");
  Config unaligned = config;
  unaligned.change.alignment.max_shift_m = 0.0;
  const std::string sent = events_with(unaligned);
  EXPECT_NE(sent.find("\"type\":\"geometry\""), std::string::npos) << sent;
}

// Maps `log` through the per-frame pass into `result` (after the nodes it holds).
FlightRun MapThroughPass(const std::filesystem::path& log, const Config& config, const FlightPassOptions& options,
                         place::PlaceRecognizer* recognizer, MapResult* result) {
  std::unique_ptr<io::FrameSource> source;
  FlightRun run;
  EXPECT_TRUE(io::OpenLog(log, config.input, &source).ok());
  EXPECT_TRUE(RunFlight(source.get(), config, options, {}, recognizer, result, nullptr, &run).ok());
  return run;
}

// Every processed frame (every 5th) of both flights is a node. Mapped together, and as a patrol against flight 1's
// saved map: the results must agree exactly. Loop closures of the second flight against the first are scored against
// the simulator's places.
TEST(MapEndToEnd, SecondFlightClosesLoopsAgainstTheFirst) {
  testing::TempDir dir;
  Config config;
  config.place.exclude_recent_s = 1e9;              // only the other flight counts here
  config.depth.source = depth::DepthSource::kNone;  // nodes and closures only: no evidence grid
  vocab::Vocabulary vocabulary;
  ASSERT_NO_FATAL_FAILURE(TwoStreetFlights(dir.path(), config, &vocabulary));
  place::PlaceRecognizer recognizer(&vocabulary, config.place);
  MapResult result;
  FlightPassOptions every;  // every processed frame: every 5th of the 30 fps logs
  every.node_every = 5;
  for (const char* flight : {"street-1", "street-2"}) MapThroughPass(dir / flight, config, every, &recognizer, &result);
  const graph::TopoMap map = BuildTopoMap(result);
  EXPECT_EQ(map.node_count(), 68);
  EXPECT_EQ(map.loop_closure_count(), static_cast<int>(result.loop_closures.size()));
  EXPECT_EQ(map.edge_count(), 66 + map.loop_closure_count());  // 33 traversals per flight
  ASSERT_TRUE(WriteMapOutputs(map, dir / "run").ok());
  // Score with the ground-truth places of both logs, as `patrolmap eval` does.
  std::vector<eval::NodeRecord> nodes;
  std::vector<eval::LoopClosureRecord> closures;
  ASSERT_TRUE(eval::ReadNodesCsv(dir / "run/nodes.csv", &nodes).ok());
  ASSERT_TRUE(eval::ReadLoopClosuresCsv(dir / "run/loop_closures.csv", &closures).ok());
  std::vector<eval::Place> places;
  std::map<std::string, std::vector<eval::Place>> by_flight;
  for (const char* flight : {"street-1", "street-2"})
    ASSERT_TRUE(eval::ReadPlaces(dir / flight, &by_flight[flight]).ok());
  for (const eval::NodeRecord& node : nodes) places.push_back(by_flight[node.flight][node.frame_index]);
  const eval::LoopClosureScore score = eval::ScoreLoopClosures(nodes, places, closures);
  EXPECT_EQ(score.nodes, 68);
  EXPECT_EQ(score.possible, 34);
  EXPECT_GE(score.found, 32);  // measured: 34

  // The same second flight as a patrol: flight 1's map saved, loaded, and flight 2 matched against the
  // file alone gives the same nodes and loop closures.
  MapResult first_only;
  place::PlaceRecognizer first_recognizer(&vocabulary, config.place);
  MapThroughPass(dir / "street-1", config, every, &first_recognizer, &first_only);
  ASSERT_TRUE(graph::SaveMap(BuildTopoMap(first_only), dir / "first.pmap").ok());
  graph::TopoMap prior;
  ASSERT_TRUE(graph::LoadMap(dir / "first.pmap", &prior).ok());
  place::PlaceRecognizer patrol_recognizer(&vocabulary, config.place);
  ASSERT_TRUE(SeedRecognizer(prior, "first.pmap", vocabulary, &patrol_recognizer).ok());
  MapResult patrol;
  MapThroughPass(dir / "street-2", config, every, &patrol_recognizer, &patrol);
  const graph::TopoMap extended = BuildTopoMap(patrol, &prior);
  EXPECT_EQ(extended.node_count(), map.node_count());
  EXPECT_EQ(extended.loop_closure_count(), map.loop_closure_count());
  const auto joint = map.Edges(), patrolled = extended.Edges();
  ASSERT_EQ(joint.size(), patrolled.size());
  for (std::size_t i = 0; i < joint.size(); ++i) {
    EXPECT_EQ(joint[i].a, patrolled[i].a);
    EXPECT_EQ(joint[i].b, patrolled[i].b);
    EXPECT_EQ(joint[i].data.inliers, patrolled[i].data.inliers);
  }
  EXPECT_EQ(score.false_positives, 0);
}

}  // namespace
}  // namespace patrolmap::pipeline

#include "patrolmap/pipeline/merge.h"

namespace patrolmap::pipeline {
namespace {

// A map of flights (patrol records only) whose objects carry `site_ids`, one list per flight; flight i starts at
// time `start` + i.
graph::TopoMap SiteMap(const std::vector<std::string>& flights, const std::vector<std::vector<int>>& site_ids,
                       TimestampNs start) {
  graph::TopoMap map;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    PatrolRecord record;
    record.flight = flights[f];
    record.has_objects = true;
    RouteFrame frame;
    frame.timestamp_ns = start + static_cast<TimestampNs>(f);
    cv::imencode(".jpg", cv::Mat(24, 32, CV_8UC1, cv::Scalar(90)), frame.jpeg);
    record.route.push_back(frame);
    for (const int id : site_ids[f]) {
      MapObject o;
      o.id = id;
      o.label = "crate";
      o.site_id = id;
      record.objects.push_back(o);
    }
    map.SetPatrol(record);
  }
  return map;
}

// Merged maps number site objects 1, 2, ... in the merge order: one input map's object (the same id in two of its
// patrols) keeps one id, and objects of different maps never share one.
TEST(Merge, SiteObjectsAreRenumberedInTheMergeOrderOneMapsObjectKeepingOneId) {
  testing::TempDir dir;
  ASSERT_TRUE(graph::SaveMap(SiteMap({"a1", "a2"}, {{1, 2}, {2, 3}}, 100), dir / "a.pmap").ok());
  ASSERT_TRUE(graph::SaveMap(SiteMap({"b1"}, {{1}}, 50), dir / "b.pmap").ok());
  MergeRequest request;
  request.maps = {dir / "a.pmap", dir / "b.pmap"};
  request.out = dir / "merged";
  request.vocabulary_path = std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc";
  MergeOutcome outcome;
  ASSERT_TRUE(RunMerge(request, &outcome).ok());
  graph::TopoMap merged;
  ASSERT_TRUE(graph::LoadMap(dir / "merged/map.pmap", &merged).ok());
  const auto ids = [&](const std::string& flight) {
    std::vector<int> sites;
    for (const MapObject& o : merged.Patrol(flight)->objects) sites.push_back(o.site_id);
    return sites;
  };
  EXPECT_EQ(ids("b1"), std::vector<int>({1}));  // b1 started first
  EXPECT_EQ(ids("a1"), std::vector<int>({2, 3}));
  EXPECT_EQ(ids("a2"), std::vector<int>({3, 4}));  // a's object 2 in both of its patrols
}

}  // namespace
}  // namespace patrolmap::pipeline
