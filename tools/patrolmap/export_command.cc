// patrolmap export MAP --format graphml|dot|json [--out FILE]
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "patrolmap/core/files.h"
#include "patrolmap/graph/export.h"
#include "patrolmap/graph/map_file.h"

namespace patrolmap::tools {
namespace {

struct ExportArguments {
  std::string map;
  std::string format = "graphml";
  std::string out;
};

int RunExport(const ExportArguments& arguments) {
  graph::TopoMap map;
  Status status = graph::LoadMap(arguments.map, &map);
  if (!status.ok()) return Fail(status);
  const bool geographic = arguments.format == "geojson" || arguments.format == "kml";
  if (geographic && !graph::HasGps(map)) {
    return Fail(Status::InvalidArgument(arguments.map + ": no node has a GPS position (the logs had no gps0/)"));
  }
  const std::string text = arguments.format == "graphml" ? graph::ToGraphML(map)
                           : arguments.format == "geojson" ? graph::ToGeoJson(map)
                           : arguments.format == "kml"     ? graph::ToKml(map)
                           : arguments.format == "dot"   ? graph::ToDot(map)
                           : arguments.format == "svg"   ? graph::ToSvg(map)
                                                         : graph::ToJson(map);
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
  app->add_option("-f,--format", arguments->format,
                  "graphml (NetworkX, Gephi, yEd), dot (Graphviz), json (node-link), svg (the layout, like paper Fig. 5), "
                  "geojson or kml (with GPS)")
      ->check(CLI::IsMember({"graphml", "dot", "json", "svg", "geojson", "kml"}))
      ->capture_default_str();
  app->add_option("-o,--out", arguments->out, "file to write (default: standard output)");
  return [arguments] { return RunExport(*arguments); };
}

}  // namespace patrolmap::tools
