// patrolmap export MAP --format graphml|dot|json [--out FILE]
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/files.h"
#include "patrolmap/eval/loop_closure_score.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/closure_matches.h"

namespace patrolmap::tools {
namespace {

struct ExportArguments {
  std::string map;
  std::string format = "graphml";
  std::string out;
  std::vector<std::string> logs;  // simulated logs of the map's flights: SVG loop closures coloured by truth
};

// Scores the map's loop closures against the logs' ground-truth places (as `patrolmap eval`).
Status SvgTruthFromLogs(const graph::TopoMap& map, const std::vector<std::string>& logs, graph::SvgTruth* truth) {
  std::map<std::string, std::vector<eval::Place>> places;
  for (const std::string& log : logs) {
    std::unique_ptr<io::FrameSource> source;
    PATROLMAP_RETURN_IF_ERROR(io::OpenLog(log, {}, &source));
    PATROLMAP_RETURN_IF_ERROR(eval::ReadPlaces(log, &places[source->info().flight_id]));
  }
  std::vector<eval::NodeRecord> nodes;
  std::vector<eval::Place> node_places;
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& node = map.node(i);
    const auto flight = places.find(node.flight);
    if (flight == places.end() || node.frame_index < 0 ||
        node.frame_index >= static_cast<std::int64_t>(flight->second.size())) {
      return Status::InvalidArgument("no --log holds the places of node " + std::to_string(i) + " (flight '" +
                                     node.flight + "')");
    }
    nodes.push_back({i, node.flight, node.timestamp_ns, node.frame_index});
    node_places.push_back(flight->second[node.frame_index]);
  }
  std::vector<eval::LoopClosureRecord> closures;
  for (const graph::TopoMap::Edge& edge : map.Edges()) {
    if (edge.data.kind == graph::EdgeKind::kLoopClosure) closures.push_back({edge.a, edge.b});
  }
  const eval::LoopClosureScore score = eval::ScoreLoopClosures(nodes, node_places, closures);
  truth->loop_closure_correct = score.correct;
  truth->missed = score.missed;
  return Status::Ok();
}

// SVG or HTML, with the loop closures judged when logs are given.
// The page shows each loop closure's verified matches (found again with the default place options).
std::string Picture(const graph::TopoMap& map, const ExportArguments& arguments, Status* status) {
  graph::SvgTruth truth;
  if (!arguments.logs.empty()) *status = SvgTruthFromLogs(map, arguments.logs, &truth);
  if (!status->ok()) return std::string();
  const graph::SvgTruth* judged = arguments.logs.empty() ? nullptr : &truth;
  if (arguments.format != "html") return graph::ToSvg(map, judged);
  const std::vector<graph::ClosureMatches> matches = pipeline::MatchClosures(map, place::PlaceOptions());
  return graph::ToHtml(map, judged, &matches);
}

int RunExport(const ExportArguments& arguments) {
  graph::TopoMap map;
  Status status = arguments.out.empty() ? Status::Ok() : RefuseOverwritingInput(arguments.out, arguments.map, "map");
  for (std::size_t i = 0; status.ok() && !arguments.out.empty() && i < arguments.logs.size(); ++i) {
    status = RefuseOverwritingInput(arguments.out, arguments.logs[i], "flight log");
  }
  if (status.ok()) status = graph::LoadMap(arguments.map, &map);
  if (!status.ok()) return Fail(status);
  const bool geographic = arguments.format == "geojson" || arguments.format == "kml";
  if (geographic && !graph::HasGps(map)) {
    return Fail(Status::InvalidArgument(arguments.map + ": no node has a GPS position (the logs had no gps0/)"));
  }
  const std::string text = arguments.format == "graphml"                             ? graph::ToGraphML(map)
                           : arguments.format == "geojson"                           ? graph::ToGeoJson(map)
                           : arguments.format == "kml"                               ? graph::ToKml(map)
                           : arguments.format == "dot"                               ? graph::ToDot(map)
                           : arguments.format == "svg" || arguments.format == "html" ? Picture(map, arguments, &status)
                                                                                     : graph::ToJson(map);
  if (!status.ok()) {
    Fail(status);
    return status.code() == StatusCode::kInvalidArgument ? 2 : 1;
  }
  if (arguments.out.empty()) {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return 0;
  }
  status = WriteFileAtomically(arguments.out, text);
  return status.ok() ? 0 : Fail(status);
}

}  // namespace

Command AddExportCommand(CLI::App* app) {
  auto arguments = std::make_shared<ExportArguments>();
  app->add_option("map", arguments->map, "map file (map.pmap)")->required();
  app->add_option(
         "-f,--format", arguments->format,
         "graphml (NetworkX, Gephi, yEd), dot (Graphviz), json (node-link), svg (the layout, like paper Fig. 5), "
         "html (a self-contained page: pan, zoom, click a node for its key frame), geojson or kml (with GPS)")
      ->check(CLI::IsMember({"graphml", "dot", "json", "svg", "html", "geojson", "kml"}))
      ->capture_default_str();
  app->add_option("-o,--out", arguments->out, "file to write (default: standard output)");
  app->add_option(
      "--log", arguments->logs,
      "svg, html: simulated logs of the map's flights; loop closures are drawn correct (green), false (red) and "
      "missed (blue) against their ground truth");
  return [arguments] { return RunExport(*arguments); };
}

}  // namespace patrolmap::tools
