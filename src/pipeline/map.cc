#include "patrolmap/pipeline/map.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "patrolmap/core/files.h"
#include "patrolmap/graph/layout.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/pipeline/data_files.h"
#include "patrolmap/vocab/descriptors.h"

namespace patrolmap::pipeline {
namespace {

cv::Mat Thumbnail(const cv::Mat& image) {
  cv::Mat thumbnail;
  const double scale = static_cast<double>(kThumbnailWidth) / image.cols;
  cv::resize(image, thumbnail, cv::Size(), scale, scale, cv::INTER_AREA);
  return thumbnail;
}

std::string Hex(std::uint64_t value) {
  char text[20];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

}  // namespace

void YawIntegrator::Add(const std::vector<ImuSample>& samples) {
  for (const ImuSample& sample : samples) {
    if (sample.accel.norm() > 1.0) up_ = (0.99 * up_ + 0.01 * sample.accel.normalized()).normalized();
    if (has_previous_) yaw_ += sample.gyro.dot(up_) * NsToSeconds(sample.timestamp_ns - previous_ns_);
    previous_ns_ = sample.timestamp_ns;
    has_previous_ = true;
  }
}

PlaceStage::PlaceStage(place::PlaceRecognizer* recognizer, MapResult* result)
    : recognizer_(recognizer), result_(result) {
  if (result_->nodes.empty()) result_->first_node = recognizer_->node_count();
}

Status PlaceStage::Add(const KeyFrameInput& input) {
  const place::KeyFrame& key_frame = input.key_frame;
  place::PlaceResult place;
  PATROLMAP_RETURN_IF_ERROR(recognizer_->AddKeyFrame(key_frame, &place));
  // The recognizer and the map number nodes alike: a node's id is its place in the recognizer.
  PATROLMAP_CHECK(place.node == result_->first_node + static_cast<int>(result_->nodes.size()));
  KeyFrameNode node = std::move(place.described);
  node.thumbnail = Thumbnail(key_frame.image);
  node.heading = input.heading;
  if (input.gps) node.gps = input.gps->head<2>();
  result_->nodes.push_back(std::move(node));
  result_->seconds_features += place.seconds_features;
  result_->seconds_query += place.seconds_query;
  result_->seconds_verify += place.seconds_verify;
  result_->seconds_add += place.seconds_add;
  if (!place.match) return Status::Ok();
  const int matched = place.match->node - result_->first_node;  // < 0: a node of the prior map
  result_->loop_closures.push_back({place.node, place.match->node, key_frame.frame_index,
                                    matched >= 0 ? result_->nodes[matched].frame_index : -1, *place.match});
  return Status::Ok();
}

Status CheckVocabulary(const graph::TopoMap& prior, const std::string& prior_path, const vocab::Vocabulary& vocabulary,
                       const std::string& vocabulary_path) {
  const graph::TopoMap::VocabularyTag& tag = prior.vocabulary();
  if (tag.fingerprint == 0 || tag.fingerprint == vocabulary.Fingerprint()) return Status::Ok();
  return Status::InvalidArgument(prior_path + " was built with the vocabulary " + tag.name + " (fingerprint " +
                                 Hex(tag.fingerprint) + "), not with " + vocabulary_path + " (fingerprint " +
                                 Hex(vocabulary.Fingerprint()) + "): give that vocabulary with --vocabulary");
}

graph::TopoMap::VocabularyTag TagOf(const vocab::Vocabulary& vocabulary, const std::string& path) {
  return {vocabulary.Fingerprint(), std::filesystem::path(path).filename().string()};
}

Status CheckNodeFits(const graph::TopoMap& map, const std::string& path, int id, const vocab::Vocabulary& vocabulary) {
  const KeyFrameNode& node = map.node(id);
  const bool words_fit = std::all_of(node.bow.words.begin(), node.bow.words.end(), [&](vocab::WordId word) {
    return word < static_cast<vocab::WordId>(vocabulary.word_count());
  });
  const int width = vocab::IsPacked(node.descriptors) ? vocab::kDescriptorDimension : node.descriptors.cols;
  if (words_fit && (node.descriptors.empty() || width == vocabulary.dimension())) return Status::Ok();
  return Status::DataLoss(path + ": node " + std::to_string(id) +
                          " was not described with this vocabulary (word ids or descriptor width out of range)");
}

Status SeedRecognizer(const graph::TopoMap& prior, const std::string& prior_path, const vocab::Vocabulary& vocabulary,
                      place::PlaceRecognizer* recognizer) {
  PATROLMAP_CHECK(recognizer->node_count() == 0);
  for (int i = 0; i < prior.node_count(); ++i) {
    PATROLMAP_RETURN_IF_ERROR(CheckNodeFits(prior, prior_path, i, vocabulary));
    const KeyFrameNode& node = prior.node(i);
    recognizer->AddDescribedNode(node);
  }
  return Status::Ok();
}

graph::TopoMap BuildTopoMap(const MapResult& result, const graph::TopoMap* prior) {
  graph::TopoMap map;
  if (prior != nullptr) map = *prior;
  PATROLMAP_CHECK(result.nodes.empty() || result.first_node == map.node_count());
  for (const KeyFrameNode& node : result.nodes) {
    const int id = map.AddNode(node);
    if (id > 0 && map.node(id - 1).flight == node.flight) map.AddEdge(id - 1, id, graph::EdgeData{});
  }
  for (const MapLoopClosure& closure : result.loop_closures) {
    const place::Verification& v = closure.verification;
    map.AddEdge(closure.query_node, closure.matched_node,
                {graph::EdgeKind::kLoopClosure, v.bow_score, v.matched_fraction, v.inliers, v.log_nfa});
  }
  return map;
}

Status WriteMapOutputs(const graph::TopoMap& map, const std::string& folder) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  std::ostringstream nodes, closures;
  nodes << "node,flight,timestamp_ns,frame_index,features\n";
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    nodes << i << "," << n.flight << "," << n.timestamp_ns << "," << n.frame_index << "," << n.points.size() << "\n";
  }
  closures << "query_node,matched_node,query_frame,matched_frame,bow_score,matched_fraction,inliers,log_nfa\n";
  char line[1200];  // room for three doubles of any size (%.4f of 1e308 is 314 characters) and the integers
  for (const graph::TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != graph::EdgeKind::kLoopClosure) continue;
    std::snprintf(line, sizeof(line), "%d,%d,%lld,%lld,%.4f,%.4f,%d,%.1f\n", e.a, e.b,
                  static_cast<long long>(map.node(e.a).frame_index), static_cast<long long>(map.node(e.b).frame_index),
                  e.data.bow_score, e.data.matched_fraction, e.data.inliers, e.data.log_nfa);
    closures << line;
  }
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/nodes.csv", nodes.str()));
  return WriteFileAtomically(folder + "/loop_closures.csv", closures.str());
}

Status LoadSiftVocabulary(const std::string& path, vocab::Vocabulary* vocabulary, std::string* loaded) {
  std::string found = path;
  if (found.empty()) PATROLMAP_RETURN_IF_ERROR(FindDefaultVocabulary(&found));
  PATROLMAP_RETURN_IF_ERROR(vocab::Vocabulary::Load(found, vocabulary));
  if (vocabulary->dimension() != 128) return Status::InvalidArgument(found + ": not a SIFT vocabulary");
  if (loaded != nullptr) *loaded = found;
  return Status::Ok();
}

Status SaveMapRun(graph::TopoMap* map, const std::string& folder, const std::string& base,
                  const graph::MapRetention& retention) {
  PATROLMAP_RETURN_IF_ERROR(graph::LayoutMap(graph::LayoutInputOf(*map), graph::LayoutOptions{}, map));
  PATROLMAP_RETURN_IF_ERROR(WriteMapOutputs(*map, folder));
  return graph::SaveMapOnto(*map, base, folder + "/map.pmap", retention);
}

}  // namespace patrolmap::pipeline
