// KML (OGC 2.2): a placemark per node with GPS and each flight's GPS track as a line.
#include <sstream>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

std::string Coordinate(const Eigen::Vector2d& latitude_longitude) {
  return Precise(latitude_longitude.y()) + "," + Precise(latitude_longitude.x()) + ",0";
}

}  // namespace

std::string ToKml(const TopoMap& map) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
      << "<name>patrolmap</name>\n";
  for (int i = 0; i < map.node_count(); ++i) {
    if (!map.node(i).gps) continue;
    out << "<Placemark><name>" << i << "</name><description>" << EscapeXml(map.node(i).flight)
        << "</description><Point><coordinates>" << Coordinate(*map.node(i).gps)
        << "</coordinates></Point></Placemark>\n";
  }
  const std::vector<std::string> flights = map.Flights();
  const std::vector<std::vector<Eigen::Vector2d>> tracks = FlightTracks(map);
  for (std::size_t f = 0; f < tracks.size(); ++f) {
    if (tracks[f].size() < 2) continue;
    out << "<Placemark><name>" << EscapeXml(flights[f]) << "</name><LineString><coordinates>";
    for (const Eigen::Vector2d& fix : tracks[f]) out << Coordinate(fix) << " ";
    out << "</coordinates></LineString></Placemark>\n";
  }
  out << "</Document>\n</kml>\n";
  return out.str();
}

}  // namespace patrolmap::graph
