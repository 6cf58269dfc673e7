// Writes the binary seeds of the fuzzing corpus: a small map file with every section (the graph tests'
// sample map, tests/sample_map.h), the same with route frames, and a small vocabulary, all through the real
// writers.
// Text seeds (configuration, EuRoC tables, times) are plain files in fuzz/corpus/.
//   seed_writer CORPUS_FOLDER
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "../src/graph/map_file_v12.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/vocab/vocabulary.h"
#include "sample_map.h"

int main(int argc, char** argv) {
  using namespace patrolmap;
  if (argc != 2 || argv[1][0] == '-') {  // "--help" is a question, not a folder to write into
    std::fprintf(stderr, "usage: seed_writer CORPUS_FOLDER\n");
    return argc == 2 && std::string(argv[1]) == "--help" ? 0 : 2;
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
  graph::TopoMap map = testing::TwoFlights();
  map.set_vocabulary({vocabulary.Fingerprint(), "seed"});
  // Each as the SQLite database (format 13) and as the binary file of format 12, which maps still migrate from.
  const auto save_both = [&corpus](const graph::TopoMap& m, const std::string& name) {
    const Status db = graph::SaveMap(m, (corpus / ("map_file/" + name + "_db.pmap")).string());
    return db.ok() ? graph::SaveLegacyMap(m, (corpus / ("map_file/" + name + ".pmap")).string()) : db;
  };
  if (status.ok()) status = save_both(map, "seed");
  // The same with two route frames (format 6): one with a pose and GPS, one without. Their bytes only start
  // like JPEG; the reader does not decode them.
  PatrolRecord record = *map.Patrol("b");
  RouteFrame frame;
  frame.timestamp_ns = 5;
  frame.frame_index = 3;
  frame.pose = record.views[0];
  frame.gps = Eigen::Vector2d(47.5, 8.25);
  frame.jpeg = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x10, 0xFF, 0xD9};
  record.route.push_back(frame);
  frame.timestamp_ns = 9;
  frame.frame_index = 4;
  frame.pose.reset();
  frame.gps.reset();
  record.route.push_back(frame);
  map.SetPatrol(record);
  if (status.ok()) status = save_both(map, "seed_route");
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  return 0;
}
