// patrolmap history MAP.pmap [--object N] [--near E N] [--radius M] [--from FLIGHT] [--to FLIGHT] [--json]
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "patrolmap/change/site_history.h"
#include "patrolmap/graph/map_file.h"

namespace patrolmap::tools {
namespace {

struct HistoryArguments {
  std::string map;
  change::SiteHistoryFilter filter;
  std::vector<double> near;  // east, north
  bool json = false;
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
};

nlohmann::json Point(const std::optional<Eigen::Vector3d>& p) {
  return p ? nlohmann::json::array({p->x(), p->y(), p->z()}) : nlohmann::json();
}

nlohmann::json HistoryJson(const std::vector<change::SiteObjectHistory>& history) {
  nlohmann::json objects = nlohmann::json::array();
  for (const change::SiteObjectHistory& h : history) {
    nlohmann::json events = nlohmann::json::array();
    for (const change::SiteEvent& e : h.events) {
      events.push_back(
          {{"patrol", e.patrol}, {"flight", e.flight}, {"what", e.what}, {"from", Point(e.from)}, {"to", Point(e.to)}});
    }
    objects.push_back({{"site_object", h.id},
                       {"label", h.label},
                       {"at", Point(h.at)},
                       {"sightings", h.sightings},
                       {"events", events}});
  }
  return {{"format", "patrolmap.history"}, {"version", 1}, {"objects", objects}};
}

void PrintHistory(const std::vector<change::SiteObjectHistory>& history) {
  for (const change::SiteObjectHistory& h : history) {
    std::printf("site object %d: %s, seen by %d patrol%s, last at (%.1f, %.1f, %.1f)\n", h.id, h.label.c_str(),
                h.sightings, h.sightings == 1 ? "" : "s", h.at->x(), h.at->y(), h.at->z());
    for (const change::SiteEvent& e : h.events) {
      const Eigen::Vector3d p = e.to ? *e.to : *e.from;
      std::printf("  patrol %d (%s): %s at (%.1f, %.1f, %.1f)", e.patrol, e.flight.c_str(), e.what.c_str(), p.x(),
                  p.y(), p.z());
      if (e.from && e.to) std::printf(", from (%.1f, %.1f, %.1f)", e.from->x(), e.from->y(), e.from->z());
      std::printf("\n");
    }
  }
  if (history.empty()) std::printf("no site object\n");
}

int RunHistory(HistoryArguments arguments) {
  pipeline::Config config;
  graph::TopoMap map;
  std::vector<change::SiteObjectHistory> history;
  if (arguments.near.size() == 2) arguments.filter.near = Eigen::Vector2d(arguments.near[0], arguments.near[1]);
  Status status = LoadCheckedConfig(arguments.config, arguments.settings, &config);
  if (status.ok()) status = graph::LoadMap(arguments.map, &map);
  if (!status.ok()) return Fail(status);
  status = change::SiteHistory(map, config.change.objects, arguments.filter, &history);
  if (!status.ok()) return Fail(Status::InvalidArgument(arguments.map + ": " + status.message()));
  if (arguments.json) {
    std::printf("%s\n", HistoryJson(history).dump(2).c_str());
  } else {
    PrintHistory(history);
  }
  return 0;
}

}  // namespace

Command AddHistoryCommand(CLI::App* app) {
  auto arguments = std::make_shared<HistoryArguments>();
  app->add_option("map", arguments->map, "map file (map.pmap)")->required();
  app->add_option("--object", arguments->filter.object, "one site object, by its id")->check(CLI::Range(0, 1 << 30));
  app->add_option("--near", arguments->near, "objects last seen near this place: east north [m], in the map's frame")
      ->expected(2)
      ->check(FiniteRange(-1e7, 1e7));
  app->add_option("--radius", arguments->filter.radius_m, "... within this distance [m]")
      ->check(FiniteRange(0.0, 1e7))
      ->capture_default_str();
  app->add_option("--from", arguments->filter.from, "from this flight on (default: the first)");
  app->add_option("--to", arguments->filter.to, "up to this flight (default: the last)");
  app->add_flag("--json", arguments->json, "print JSON (format patrolmap.history) instead of text");
  app->add_option("-c,--config", arguments->config, "YAML configuration (change.objects.* keys)");
  AddSetOption(app, &arguments->settings);
  app->footer(
      "Lists the site's objects over the patrols the map holds: each keeps one id across patrols (a patrol's "
      "object found persistent or moved keeps the id of the one before). Per object: first seen, moved, not seen "
      "(a later patrol covered its place and did not detect it), seen again.");
  return [arguments] { return RunHistory(*arguments); };
}

}  // namespace patrolmap::tools
