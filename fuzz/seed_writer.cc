// Writes the binary seeds of the fuzzing corpus: a small map file with every section (two flights, loop
// closures, a patrol record with an object and a grid) and a small vocabulary, both through the real
// writers. Text seeds (configuration, EuRoC tables, times) are plain files in fuzz/corpus/.
//   seed_writer CORPUS_FOLDER
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "patrolmap/graph/map_file.h"
#include "patrolmap/vocab/vocabulary.h"

namespace patrolmap {
namespace {

graph::TopoMap SmallMap(const vocab::Vocabulary& vocabulary) {
  graph::TopoMap map;
  cv::RNG rng(5);
  for (int i = 0; i < 4; ++i) {
    graph::NodeData node;
    node.flight = i < 2 ? "a" : "b";
    node.timestamp_ns = SecondsToNs(10.0 * i);
    node.frame_index = 30 * i;
    node.thumbnail = cv::Mat(6, 8, CV_8UC1);
    rng.fill(node.thumbnail, cv::RNG::UNIFORM, 0, 255);
    for (int k = 0; k < 3; ++k) node.keypoints.emplace_back(cv::Point2f(k * 2.5f, i + 0.5f), 2.0f, 30.0f * k, 0.5f, 1);
    node.descriptors = cv::Mat(3, 128, CV_8UC1);
    rng.fill(node.descriptors, cv::RNG::UNIFORM, 0, 255);
    cv::Mat floats;
    node.descriptors.convertTo(floats, CV_32F);
    vocabulary.Transform(floats, &node.bow);
    if (i == 1) node.gps = Eigen::Vector2d(47.35, 8.43);
    node.layout = Eigen::Vector2d(i, -i);
    const int id = map.AddNode(node);
    if (id == 1 || id == 3) map.AddEdge(id - 1, id, graph::EdgeData{});
  }
  map.AddEdge(2, 0, {graph::EdgeKind::kLoopClosure, 0.41, 0.62, 88});
  PatrolRecord record;
  record.flight = "b";
  record.camera = {180.5, 181.5, 94.0, 60.0, 188, 120};
  record.feature_image_width = 188;
  record.views.push_back({123, Eigen::Vector3d(1.5, -2.25, 3.0), Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5)});
  record.has_objects = true;
  MapObject object;
  object.id = 3;
  object.label = "crate";
  object.confidence = 0.71;
  object.detections = 12;
  object.centroid = Eigen::Vector3d(10.125, -3.5, 0.5);
  object.box_min = object.centroid - Eigen::Vector3d::Constant(0.5);
  object.box_max = object.centroid + Eigen::Vector3d::Constant(0.5);
  object.points = {Eigen::Vector3f(10.0f, -3.0f, 0.25f)};
  object.descriptor = {0.5f, 0.5f};
  object.labels = {{"crate", 7.5, 10}};
  object.first_seen_ns = 5, object.last_seen_ns = 99;
  record.objects.push_back(object);
  record.grid.voxel_size = 0.2;
  record.grid.voxels = {{-3, 0, 1, 2, 7}, {5, -2, 2, 9, 1}};
  map.SetPatrol(record);
  map.set_vocabulary({vocabulary.Fingerprint(), "seed"});
  return map;
}

}  // namespace
}  // namespace patrolmap

int main(int argc, char** argv) {
  using namespace patrolmap;
  if (argc != 2) {
    std::fprintf(stderr, "usage: seed_writer CORPUS_FOLDER\n");
    return 2;
  }
  const std::filesystem::path corpus = argv[1];
  std::filesystem::create_directories(corpus / "vocabulary");
  std::filesystem::create_directories(corpus / "map_file");
  std::vector<cv::Mat> images(4);
  cv::RNG rng(7);
  for (cv::Mat& image : images) {
    image = cv::Mat(20, 128, CV_32F);
    rng.fill(image, cv::RNG::UNIFORM, 0.0f, 255.0f);
  }
  vocab::VocabularyOptions options;
  options.branching = 3;
  options.depth = 2;
  vocab::Vocabulary vocabulary;
  Status status = vocab::Vocabulary::Train(images, options, &vocabulary);
  if (status.ok()) status = vocabulary.Save((corpus / "vocabulary/seed.pmvoc").string());
  if (status.ok()) status = graph::SaveMap(SmallMap(vocabulary), (corpus / "map_file/seed.pmap").string());
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  return 0;
}
