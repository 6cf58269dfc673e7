// changes.kml (OGC KML 2.2): both flights' GPS tracks, then every change as a placemark whose balloon shows
// its before and after pictures.
#include <cstdio>
#include <sstream>

#include "patrolmap/change/report.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::change {
namespace {

std::string Coordinate(double longitude, double latitude) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.9f,%.9f,0", longitude, latitude);
  return buffer;
}

std::string Coordinate(const GeoReference& geo, const Eigen::Vector3d& world) {
  const Eigen::Vector2d lat_lon = geo.LatitudeLongitude(world);
  return Coordinate(lat_lon.y(), lat_lon.x());
}

void Track(const graph::TopoMap& map, const std::string& flight, std::ostringstream* out) {
  const PatrolRecord* record = map.Patrol(flight);
  if (record == nullptr) return;
  std::ostringstream line;
  int fixes = 0;
  for (const RouteFrame& frame : record->route) {
    if (frame.gps) line << Coordinate(frame.gps->y(), frame.gps->x()) << " ", ++fixes;
  }
  if (fixes < 2) return;
  *out << "<Placemark><name>" << graph::EscapeXml(flight) << " (GPS track)</name><LineString><coordinates>"
       << line.str() << "</coordinates></LineString></Placemark>\n";
}

std::string Picture(const ChangeItem& item, bool before, const std::string& images) {
  const ChangeView& view = before ? item.before : item.after;
  if (view.image.empty()) return "";
  char caption[160];
  std::snprintf(caption, sizeof(caption), "%s: %s, %.1f s, frame %lld", before ? "before" : "after",
                view.flight.c_str(), NsToSeconds(view.timestamp_ns), static_cast<long long>(view.frame_index));
  return "<p>" + graph::EscapeXml(caption) + "<br/><img src=\"" +
         graph::EscapeXml(images + "/" + ViewFileName(item, before)) + "\"/></p>";
}

}  // namespace

std::string ToKml(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                  const GeoReference& geo, const std::string& images) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
      << "<name>" << graph::EscapeXml("Changes from " + report.prior_flight + " to " + report.current_flight)
      << "</name>\n";
  Track(map, report.prior_flight, &out);
  Track(map, report.current_flight, &out);
  for (const ChangeItem& item : items) {
    if (!item.position && !item.bearing) continue;
    char summary[96];
    if (item.position) {
      std::snprintf(summary, sizeof(summary), "confidence %.2f, height %.1f m", item.confidence, item.position->z());
    } else {
      std::snprintf(summary, sizeof(summary), "confidence %.2f, somewhere along this bearing from the camera",
                    item.confidence);
    }
    const std::string description = "<p>" + graph::EscapeXml(item.id) + ": " + graph::EscapeXml(item.kind) + " " +
                                    graph::EscapeXml(item.state) + ", " + graph::EscapeXml(item.label) + ", " +
                                    summary + "</p>" + Picture(item, true, images) + Picture(item, false, images);
    out << "<Placemark id=\"" << graph::EscapeXml(item.id) << "\"><name>" << item.number << " "
        << graph::EscapeXml(item.kind + " " + item.state) << "</name><description><![CDATA[" << description
        << "]]></description>";
    if (item.position) {
      out << "<Point><coordinates>" << Coordinate(geo, *item.position) << "</coordinates></Point>";
    } else {
      out << "<LineString><coordinates>" << Coordinate(geo, item.bearing->origin) << " "
          << Coordinate(geo, BearingEnd(item)) << "</coordinates></LineString>";
    }
    out << "</Placemark>\n";
  }
  out << "</Document>\n</kml>\n";
  return out.str();
}

}  // namespace patrolmap::change
