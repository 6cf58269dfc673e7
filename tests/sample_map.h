// A small map with every part a map file holds (two flights, traversals, loop closures, GPS, a patrol
// record with an object and an evidence grid): the graph tests' fixture and the fuzzing seed.
#pragma once

#include <opencv2/core.hpp>

#include "patrolmap/graph/topo_map.h"

namespace patrolmap::testing {

// Flight a: nodes 0-1-2-3 in a row; flight b: 4-5-6. Loop closures 4~1 and 6~3, and 5~1 (same place as 4).
inline graph::TopoMap TwoFlights() {
  using graph::EdgeData;
  using graph::EdgeKind;
  using graph::TopoMap;
  TopoMap map;
  cv::RNG rng(3);
  for (int i = 0; i < 7; ++i) {
    KeyFrameNode node;
    node.flight = i < 4 ? "a" : "b";
    node.timestamp_ns = SecondsToNs(10.0 * i);
    node.frame_index = 30 * i;
    node.thumbnail = cv::Mat(12, 16, CV_8UC1);
    rng.fill(node.thumbnail, cv::RNG::UNIFORM, 0, 255);
    for (int k = 0; k < 5; ++k) node.points.emplace_back(k * 3.5f, i + 0.25f);
    node.descriptors = cv::Mat(5, 128, CV_8UC1);
    rng.fill(node.descriptors, cv::RNG::UNIFORM, 0, 255);
    node.bow.words = {static_cast<vocab::WordId>(i), 100};
    node.bow.weights = {0.25f, 0.75f};
    if (i == 2) node.gps = Eigen::Vector2d(47.3572123456789, 8.4370987654321);
    node.layout = Eigen::Vector2d(i, -i);
    const int id = map.AddNode(node);
    if (id != 0 && id != 4) map.AddEdge(id - 1, id, EdgeData{});
  }
  map.AddEdge(4, 1, {EdgeKind::kLoopClosure, 0.41, 0.62, 88});
  map.AddEdge(6, 3, {EdgeKind::kLoopClosure, 0.33, 0.51, 71});
  map.AddEdge(5, 1, {EdgeKind::kLoopClosure, 0.21, 0.35, 55});
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
  object.points = {Eigen::Vector3f(10.0f, -3.0f, 0.25f), Eigen::Vector3f(10.5f, -3.5f, 0.75f)};
  object.descriptor = {0.5f, 0.25f, 0.25f};
  object.labels = {{"crate", 7.5, 10}, {"barrel", 1.0, 2}};
  object.first_seen_ns = 5, object.last_seen_ns = 99;
  record.objects.push_back(object);
  record.grid.voxel_size = 0.2;
  record.grid.voxels = {{-3, 0, 1, 2, 7}, {-3, 1, 0, 0, 4}, {5, -2, 2, 9, 1}};
  record.grid.evicted_voxels = 11;
  record.depth_source = "stereo";
  map.SetPatrol(record);
  return map;
}

}  // namespace patrolmap::testing
