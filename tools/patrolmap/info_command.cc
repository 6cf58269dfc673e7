// patrolmap info MAP|BAG
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/words.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/bag.h"

namespace patrolmap::tools {
namespace {

// A bag's topics: name, type, messages and rate, as `rosbag info` and `ros2 bag info` list them.
int RunBagInfo(const std::string& path) {
  std::vector<io::BagTopic> topics;
  const Status status = io::ListBagTopics(path, &topics);
  if (!status.ok()) return Fail(status);
  std::printf("%s: %zu %s\n", path.c_str(), topics.size(), topics.size() == 1 ? "topic" : "topics");
  for (const io::BagTopic& topic : topics) {
    std::printf("  %-36s %-36s %8lld msgs", topic.name.c_str(), topic.type.c_str(),
                static_cast<long long>(topic.count));
    if (topic.rate_hz > 0.0) std::printf(" %8.2f Hz", topic.rate_hz);
    std::printf("\n");
  }
  return 0;
}

// A patrol's camera, its lens when it distorts, and where its poses came from, as far as the log gave them.
void PrintCamera(const PatrolRecord& record) {
  if (record.camera.valid()) {
    std::printf(", camera %dx%d (fx %.1f)", record.camera.width, record.camera.height, record.camera.fx);
  }
  const Distortion& d = record.distortion;
  if (d != Distortion{}) std::printf(" through a lens (k1 %.4g, k2 %.4g, p1 %.4g, p2 %.4g)", d[0], d[1], d[2], d[3]);
  if (!record.pose_source.empty()) std::printf(", poses from %s", record.pose_source.c_str());
}

int RunInfo(const std::string& path, bool verbose) {
  if (io::IsBag(path)) return RunBagInfo(path);
  graph::TopoMap map;
  const Status status = graph::LoadMap(path, &map);
  if (!status.ok()) return Fail(status);
  int within = 0, across = 0, traversals = 0;
  for (const graph::TopoMap::Edge& edge : map.Edges()) {
    if (edge.data.kind == graph::EdgeKind::kTraversal)
      ++traversals;
    else if (map.node(edge.a).flight == map.node(edge.b).flight)
      ++within;
    else
      ++across;
  }
  std::printf("%s: %.1f KB, %s, %s, %s, %s (%d within flights, %d across)\n", path.c_str(),
              std::filesystem::file_size(path) / 1024.0,
              Counted(static_cast<long long>(map.Flights().size()), "flight", "flights").c_str(),
              Counted(map.node_count(), "node", "nodes").c_str(),
              Counted(traversals, "traversal", "traversals").c_str(),
              Counted(within + across, "loop closure", "loop closures").c_str(), within, across);
  for (const std::string& flight : map.Flights()) {
    const PatrolRecord* record = map.Patrol(flight);
    int nodes = 0;
    for (int i = 0; i < map.node_count(); ++i) nodes += map.node(i).flight == flight;
    const auto span = map.FlightSpan(flight).value_or(std::make_pair(TimestampNs{0}, TimestampNs{0}));
    std::printf("  flight %-24s %9s, %.1f-%.1f s", flight.c_str(), Counted(nodes, "node", "nodes").c_str(),
                NsToSeconds(span.first), NsToSeconds(span.second));
    if (record != nullptr && record->has_objects) {
      const auto confirmed =
          std::count_if(record->objects.begin(), record->objects.end(), [](const MapObject& o) { return o.confirmed; });
      std::printf(", %zu objects (%zu unconfirmed)", static_cast<std::size_t>(confirmed),
                  record->objects.size() - static_cast<std::size_t>(confirmed));
    }
    if (record != nullptr && record->grid.voxel_size > 0) {
      std::printf(", evidence grid %zu voxels of %.2f m%s", record->grid.voxels.size(), record->grid.voxel_size,
                  record->archived ? " (archived: those no later patrol observed)" : "");
    }
    if (record != nullptr && !record->route.empty()) {
      std::size_t bytes = 0;
      for (const RouteFrame& frame : record->route) bytes += frame.jpeg.size();
      std::printf(", %s along the route (%.1f MB)",
                  Counted(static_cast<long long>(record->route.size()), "frame", "frames").c_str(), bytes / 1048576.0);
    }
    if (record != nullptr) PrintCamera(*record);
    std::printf("\n");
    if (record != nullptr && !record->source.empty()) {
      std::printf("    read from %s%s\n", record->source.c_str(),
                  record->source_digest.empty() ? "" : (" (content " + record->source_digest + ")").c_str());
    }
    if (record == nullptr || !verbose) continue;
    for (const MapObject& o : record->objects) {
      std::printf("    object %3d %-10s confidence %.2f, %3d detections at (%.2f, %.2f, %.2f), %zu points%s\n", o.id,
                  o.label.c_str(), o.confidence, o.detections, o.centroid.x(), o.centroid.y(), o.centroid.z(),
                  o.points.size(), o.confirmed ? "" : ", unconfirmed");
    }
  }
  return 0;
}

}  // namespace

Command AddInfoCommand(CLI::App* app) {
  auto path = std::make_shared<std::string>();
  auto verbose = std::make_shared<bool>(false);
  app->add_option("file", *path, "a map file (map.pmap), or a ROS bag (.bag, or a ROS 2 bag folder) to list its topics")
      ->required();
  app->add_flag("-v,--verbose", *verbose, "list every flight's objects");
  return [path, verbose] { return RunInfo(*path, *verbose); };
}

}  // namespace patrolmap::tools
