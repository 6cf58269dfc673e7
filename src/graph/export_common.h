// Helpers the export formats share (export_*.cc).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "patrolmap/graph/export.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

// A double with 17 significant digits (enough to read back the same value).
std::string Precise(double value);

// Each flight's colour in the map's pictures (by its index in map.Flights(), modulo 5); clear of the verdict
// colours (green, red, blue).
inline constexpr const char* kFlightColours[] = {"#374151", "#d97706", "#7c3aed", "#0f766e", "#a16207"};

// Each flight's GPS track as latitude, longitude [deg], in the order of map.Flights(): the fixes of its kept
// route frames (PatrolRecord::route) when it has two or more, else its nodes' positions.
std::vector<std::vector<Eigen::Vector2d>> FlightTracks(const TopoMap& map);

// JSON to embed in an HTML <script> element: '<', '>' and '&' become their JSON escapes (\u003c ...), so no
// string from a log can end the element early (a flight id "x</script><img ...>").
std::string JsonForScript(const nlohmann::json& value);

// The layout picture (ToSvg): fitted to its content, with the legend inside it or not (the HTML page shows
// the legend beside it). Loop closures are curves (class "closure", data-edge its index among the closures);
// one between nodes drawn at the same spot is a ring around them.
std::string SvgDrawing(const TopoMap& map, const SvgTruth* truth, bool legend);

}  // namespace patrolmap::graph
