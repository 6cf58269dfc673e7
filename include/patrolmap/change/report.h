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
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/change_location.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/geo_reference.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/route_compare.h"
#include "patrolmap/change/site_history.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::change {

struct PlaceChange {
  int prior_node = -1, current_node = -1;  // map nodes (a loop closure between the two flights)
  AppearanceChange appearance;
  ChangeLocation location;  // of its largest region: on the current evidence grid, else a bearing (change_location.h)
};

// A patrol whose evidence grid the comparison's reference took voxels from (site_state.h), and when it was flown.
struct GridSource {
  std::string flight;
  long long voxels = 0;
  TimestampNs flown_ns = 0;  // its first node's or route frame's time
};

struct ChangeReport {
  std::string prior_flight, current_flight;
  std::vector<PlaceChange> places;  // every place both patrols saw (their key frames compared when the route is not)
  RouteComparison route;            // appearance along the route, when both patrols kept route frames
  bool objects_compared = false;    // both patrols had detections and poses
  std::vector<ObjectChange> objects;
  bool geometry_compared = false;  // both patrols had depth and poses
  GeometryChange geometry;
  // The patrols the geometry was compared with, newest first: the prior flight, then earlier ones for the regions
  // only they observed (the latest state of the site).
  std::vector<GridSource> grid_sources;
  std::string pose_prior, pose_current;  // where each patrol's camera poses came from (PatrolRecord::pose_source)
  double seconds_appearance = 0.0, seconds_objects = 0.0, seconds_geometry = 0.0;
  // The histories of the site objects its object changes concern, over the map's patrols (SiteHistoriesOf).
  std::vector<SiteObjectHistory> site_objects;

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

// Which finding of a report an item shows: its list ("objects", "geometry", "places", "route") and its index there.
struct ReportSource {
  std::string list;
  int index = -1;
};

// What one channel found of a change that another channel's entry leads (ChangeItem::evidence).
struct ChangeEvidence {
  std::string channel;  // ChangeItem::channels
  std::string id, kind, state, label, located;
  double confidence = 0.0;
  std::optional<Eigen::Vector3d> position;
  ReportSource source;
};

// One change for the inspector: an object that is new, removed or moved, a changed geometry region, or a
// place whose appearance changed; with what the other channels found of the same physical change (FuseItems).
struct ChangeItem {
  std::string id;
  int number = 0;           // 1, 2, ... in report order: the plan's markers and the table's rows
  std::string kind;         // "object", "geometry", "appearance"
  std::string state;        // objects: new, removed, moved; geometry: appeared, vanished; appearance: changed
  std::string label;        // objects: the class; geometry: "N voxels"; appearance: "N regions"
  double confidence = 0.0;  // in [0, 1]
  std::optional<Eigen::Vector3d> position;  // world frame [m]; none without poses, or for a bearing
  std::optional<Eigen::Vector3d> from;      // moved objects: the prior position
  int site_object = -1;                     // detected objects: the site object (change/site_objects.h); -1 for none
  // Appearance: how its position was found ("depth", "grid", "triangulated", or "bearing" with no position: the
  // ray from the camera it lies on; "none" without poses). Empty for objects and geometry, placed by 3D evidence.
  std::string located;
  std::optional<Bearing> bearing;
  double bearing_range_m = 0.0;  // how far along its bearing it may lie (ReportOptions::max_view_range_m) [m]
  // Where it is, in the world [m]: an object's boxes where it was and where it is, a region's box, an appearance
  // change's point; empty for a bearing.
  std::vector<Eigen::AlignedBox3d> extent;
  // The channels that saw it ("detections", "geometry objects", "geometry", "appearance"), its own first, and the
  // findings of the others fused into it.
  std::vector<std::string> channels;
  std::vector<ChangeEvidence> evidence;
  // Whether the two patrols' geometry was compared where it is (GeometryChange::ComparedNear, at each end of a move):
  // false when no depth of one patrol or the other reached it, so the geometry channel could not have seen it; none
  // when the geometry was not compared at all, or for a bearing.
  std::optional<bool> compared_in_3d;
  ReportSource source;
  ChangeView before, after;
};

struct ReportOptions {
  int crop_size_px = 240;  // the longer side of each before/after picture
  // Findings of several channels are one change where they lie within this of each other [m] (FuseItems).
  double fuse_distance_m = 1.0;
  double crop_margin = 0.6;        // a crop extends the change's box by this share of its size on each side
  double max_view_range_m = 30.0;  // kept frames farther from the change do not show it
};

// One entry per physical change: each item of another channel joins the first entry (objects, then geometry
// regions, then appearance, each in report order) that it lies on. A region lies on an entry whose extent, grown by
// fuse_distance_m, its box meets; an appearance change on one whose grown extent the line of sight from its camera to
// its point (and fuse_distance_m beyond) crosses, the nearest to that point first: a removed object's place shows
// the wall behind it. An entry's confidence is that of independent witnesses, 1 - the product of (1 - each one's).
// A bearing without a point joins nothing. Items that join nothing stay entries of their own.
std::vector<ChangeItem> FuseItems(std::vector<ChangeItem> items, double fuse_distance_m);

// The changes of `report`, fused (FuseItems) and numbered, each with its before and after pictures from the two
// patrols' kept frames (appearance: the two key frames).
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

// The ids `items` (entries and their evidence) give the findings of report list `list`, by index ("" where none).
std::vector<std::string> IdsOf(const std::vector<ChangeItem>& items, const std::string& list, std::size_t count);

// The far end of a change's bearing (ChangeItem::bearing, bearing_range_m along it).
Eigen::Vector3d BearingEnd(const ChangeItem& item);

// What a reader of changes.json gets back (ReadChangesJson): the flights compared, the summary, the objects as
// reported and the change list's entries. Positions are in the map's frame [m].
struct ChangesFile {
  std::string prior_flight, current_flight;
  int places_compared = 0, places_changed = 0;
  struct Object {
    std::string id, state, label;
    bool from_geometry = false;  // a class-agnostic object of changed geometry ("source": "geometry")
    std::optional<Eigen::Vector3d> before, after;
  };
  bool objects_compared = false;  // "objects" is an array (null when the patrols had no detections)
  std::vector<Object> objects;
  struct Entry {
    std::string id;
    std::optional<Eigen::Vector3d> position, from;  // null for a bearing; `from` where a moved object was
  };
  std::vector<Entry> entries;
};

// Reads a changes.json that ToJson wrote. A file that is not one, or is malformed, is DataLoss naming the file and
// what is wrong.
Status ReadChangesJson(const std::string& path, ChangesFile* file);

// The file name of a change's picture: "<id>-before.jpg" or "<id>-after.jpg".
std::string ViewFileName(const ChangeItem& item, bool before);

// Writes DIR/changes.json, DIR/changes.html and the pictures in DIR/changes_images/, and with GPS
// DIR/changes.geojson and DIR/changes.kml, each file atomically. `items` (may be null) receives the entries written.
Status WriteChangeReport(const ChangeReport& report, const graph::TopoMap& map, const std::string& folder,
                         std::vector<ChangeItem>* items = nullptr);

}  // namespace patrolmap::change
