// Mapping a flight log: key locations (flow stage) become nodes, and place
// recognition closes loops between them (DESIGN.md: io -> flow -> place).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/place/place_recognizer.h"

namespace patrolmap::pipeline {

constexpr int kThumbnailWidth = 160;

struct MapLoopClosure {
  int query_node = 0;
  int matched_node = 0;
  std::int64_t query_frame = 0;
  std::int64_t matched_frame = 0;
  place::Verification verification;
};

struct MapResult {
  // The nodes added, each as the map keeps it (thumbnail kThumbnailWidth pixels wide); nodes[i] has id
  // first_node + i (a prior map's nodes come first).
  std::vector<KeyFrameNode> nodes;
  int first_node = 0;
  std::vector<MapLoopClosure> loop_closures;
  // Summed over key frames [s] (the paper's Table IV split).
  double seconds_features = 0.0, seconds_query = 0.0, seconds_verify = 0.0, seconds_add = 0.0;
};

// Integrates the gyro's yaw rate about the measured up axis (the accelerometer's mean direction), so the IMU
// may be mounted any way round: the heading a node keeps.
class YawIntegrator {
 public:
  void Add(const std::vector<ImuSample>& samples);
  double yaw() const { return yaw_; }

 private:
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  double yaw_ = 0.0;
  TimestampNs previous_ns_ = 0;
  bool has_previous_ = false;
};

// A frame chosen as a node, at the place stage's scale, with what the map keeps of it besides its features.
struct KeyFrameInput {
  place::KeyFrame key_frame;
  double heading = 0.0;
  std::optional<Eigen::Vector3d> gps;
  std::optional<CameraPoseSample> pose;  // when the log has poses
};

// The place stage of a mapping run: recognises each key frame's place and records its node and loop
// closure in `result` (which may hold the nodes of earlier flights).
class PlaceStage {
 public:
  PlaceStage(place::PlaceRecognizer* recognizer, MapResult* result);
  Status Add(const KeyFrameInput& input);
  const MapResult& result() const { return *result_; }
  const place::PlaceRecognizer& recognizer() const { return *recognizer_; }

 private:
  place::PlaceRecognizer* recognizer_;
  MapResult* result_;
};

// The topological map of a mapping run: the nodes with their thumbnails and
// features, traversal edges between consecutive nodes of a flight, and the
// verified loop closures. `prior` (may be null) holds nodes already in the
// recognizer before this run, which come first with their edges.
graph::TopoMap BuildTopoMap(const MapResult& result, const graph::TopoMap* prior = nullptr);

// Fails naming both files when `prior` records another vocabulary than `vocabulary` (maps that record
// none pass).
Status CheckVocabulary(const graph::TopoMap& prior, const std::string& prior_path, const vocab::Vocabulary& vocabulary,
                       const std::string& vocabulary_path);

// What a map records of the vocabulary at `path` (TopoMap::set_vocabulary).
graph::TopoMap::VocabularyTag TagOf(const vocab::Vocabulary& vocabulary, const std::string& path);

// Fails naming the map file and the node when node `id`'s words or descriptors do not fit `vocabulary`.
Status CheckNodeFits(const graph::TopoMap& map, const std::string& path, int id, const vocab::Vocabulary& vocabulary);

// Puts a prior map's nodes (their stored features and BoW vectors) into an
// empty recognizer, in order, so a later flight is matched against them. Fails naming the map when a node's
// words or descriptors do not fit `vocabulary`.
Status SeedRecognizer(const graph::TopoMap& prior, const std::string& prior_path, const vocab::Vocabulary& vocabulary,
                      place::PlaceRecognizer* recognizer);

// Loads the SIFT vocabulary the place stage needs (the default one, FindDefaultVocabulary, when `path` is
// empty); fails naming the file when it is not one. `loaded` (may be null) receives the file's path.
Status LoadSiftVocabulary(const std::string& path, vocab::Vocabulary* vocabulary, std::string* loaded = nullptr);

// Lays the map out (graph::LayoutMap) and writes DIR/nodes.csv, DIR/loop_closures.csv and DIR/map.pmap: a copy of
// the map file `base` the run read and grew (graph::SaveMapOnto), or the whole map when `base` is empty; older
// patrols archived as `retention` says.
Status SaveMapRun(graph::TopoMap* map, const std::string& folder, const std::string& base,
                  const graph::MapRetention& retention);

// Writes the whole map as DIR/nodes.csv (node,flight,timestamp_ns,frame_index,
// features) and DIR/loop_closures.csv (query_node,matched_node,query_frame,
// matched_frame,bow_score,matched_fraction,inliers), each atomically.
Status WriteMapOutputs(const graph::TopoMap& map, const std::string& folder);

}  // namespace patrolmap::pipeline
