// The change report between two patrols of a map: per place the appearance change, per object its state, and
// the changed geometry. WriteChangeReport writes it for people and for tools:
//   changes.json     format "patrolmap.changes", version 2 (docs/changes.schema.json)
//   changes.html     one page: a plan of both flights with every change as a numbered marker, and per change
//                    its before and after pictures (images in changes_images/, loaded lazily)
//   changes.geojson  (RFC 7946) and changes.kml: every change at its longitude and latitude, when the current
//                    flight has GPS to tie its world frame to the globe
// Every change has a stable id (ChangeId), the same in all of them and in patrolmap-onboard's events.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/geo_reference.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/route_compare.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

struct PlaceChange {
  int prior_node = -1, current_node = -1;  // map nodes (a loop closure between the two flights)
  AppearanceChange appearance;
};

struct ChangeReport {
  std::string prior_flight, current_flight;
  std::vector<PlaceChange> places;  // every place both patrols saw (their key frames compared when the route is not)
  RouteComparison route;            // appearance along the route, when both patrols kept route frames
  bool objects_compared = false;    // both patrols had detections and poses
  std::vector<ObjectChange> objects;
  bool geometry_compared = false;  // both patrols had depth and poses
  GeometryChange geometry;
  std::string pose_prior, pose_current;  // where each patrol's camera poses came from (PatrolRecord::pose_source)
  double seconds_appearance = 0.0, seconds_objects = 0.0, seconds_geometry = 0.0;

  int ChangedPlaces() const;
  int ObjectsIn(ObjectState state) const;
};

// Stable ids: "object-p<prior id>-c<current id>" (-1 where the object is not in that patrol),
// "geometry-<x>_<y>_<z>" (the 2 m cell of the region's centroid), "appearance-<prior node>-<current node>"
// (key frames of a place).
// In a report, a later change with the same id (two regions in one cell) gets "-2", "-3", ... appended.
std::string ObjectChangeId(const ObjectChange& change);
std::string GeometryChangeId(const Eigen::Vector3d& centroid);
std::string AppearanceChangeId(int prior_node, int current_node);
// A change along the route: "appearance-f<prior frame index>-<current frame index>" of its best view's frames.
std::string RouteChangeId(const RouteFrame& prior, const RouteFrame& current);

// What one patrol saw of a change: the kept frame (PatrolRecord::route) that showed it best, cropped around
// it with the change outlined.
struct ChangeView {
  std::string flight;
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = -1;  // -1: no kept frame of this patrol showed it
  cv::Mat image;                  // BGR, the change outlined in red
};

// One change for the inspector: an object that is new, removed or moved, a changed geometry region, or a
// place whose appearance changed.
struct ChangeItem {
  std::string id;
  int number = 0;           // 1, 2, ... in report order: the plan's markers and the table's rows
  std::string kind;         // "object", "geometry", "appearance"
  std::string state;        // objects: new, removed, moved; geometry: appeared, vanished; appearance: changed
  std::string label;        // objects: the class; geometry: "N voxels"; appearance: "N regions"
  double confidence = 0.0;  // in [0, 1]
  std::optional<Eigen::Vector3d> position;  // world frame [m]; the camera's for appearance; none without poses
  std::optional<Eigen::Vector3d> from;      // moved objects: the prior position
  ChangeView before, after;
};

struct ReportOptions {
  int crop_size_px = 240;          // the longer side of each before/after picture
  double crop_margin = 0.6;        // a crop extends the change's box by this share of its size on each side
  double max_view_range_m = 30.0;  // kept frames farther from the change do not show it
};

// The changes of `report`, numbered, each with its before and after pictures from the two patrols' kept
// frames (appearance: the two key frames).
std::vector<ChangeItem> ReportItems(const ChangeReport& report, const graph::TopoMap& map,
                                    const ReportOptions& options = ReportOptions());

// The writers; `images` is the folder of the pictures relative to the page ("" embeds them in the page).
std::string ToJson(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                   const std::optional<GeoReference>& geo, const std::string& images);
std::string ToHtml(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                   const std::optional<GeoReference>& geo, const std::string& images);
// Both flights' GPS tracks and camera paths as lines, then every change with a position as a point.
std::string ToGeoJson(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                      const GeoReference& geo);
std::string ToKml(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                  const GeoReference& geo, const std::string& images);

// The file name of a change's picture: "<id>-before.jpg" or "<id>-after.jpg".
std::string ViewFileName(const ChangeItem& item, bool before);

// Writes DIR/changes.json, DIR/changes.html and the pictures in DIR/changes_images/, and with GPS
// DIR/changes.geojson and DIR/changes.kml, each file atomically.
Status WriteChangeReport(const ChangeReport& report, const graph::TopoMap& map, const std::string& folder);

}  // namespace patrolmap::change
