#include "patrolmap/change/report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/core/files.h"

namespace patrolmap::change {
namespace {

constexpr double kRegionCellM = 2.0;   // geometry ids: one per region centroid in a cell this wide
const cv::Scalar kOutline(0, 0, 230);  // BGR

std::array<Eigen::Vector3d, 8> Corners(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[i] =
        Eigen::Vector3d((i & 1) ? high.x() : low.x(), (i & 2) ? high.y() : low.y(), (i & 4) ? high.z() : low.z());
  }
  return corners;
}

// A kept frame and where a box lies in it (camera pixels).
struct Sighting {
  const RouteFrame* frame = nullptr;
  cv::Rect2d box;
};

// Whether the patrol's evidence grid has an occupied voxel on the line of sight from `eye` to the box (its
// centre, stopping short of the box): then the frame shows what stands in front, not the change.
bool Occluded(const EvidenceGridData& grid, const Eigen::Vector3d& eye, const Eigen::Vector3d& low,
              const Eigen::Vector3d& high) {
  if (grid.voxel_size <= 0.0 || grid.voxels.empty()) return false;
  const Eigen::Vector3d centre = (low + high) / 2.0, ray = centre - eye;
  const double stop = ray.norm() - (high - low).norm() / 2.0 - grid.voxel_size;
  for (double t = grid.voxel_size; t < stop; t += grid.voxel_size) {
    const Eigen::Vector3d p = (eye + ray.normalized() * t) / grid.voxel_size;
    VoxelEvidence key;
    key.x = static_cast<std::int32_t>(std::lround(p.x()));
    key.y = static_cast<std::int32_t>(std::lround(p.y()));
    key.z = static_cast<std::int32_t>(std::lround(p.z()));
    const auto it = std::lower_bound(grid.voxels.begin(), grid.voxels.end(), key, VoxelBefore);
    if (it == grid.voxels.end() || VoxelBefore(key, *it)) continue;
    if (it->hits >= 2 && 2 * it->hits >= it->passes) return true;  // occupancy at least a third
  }
  return false;
}

// Times a patrol's frames may show a change from: without an evidence grid to see what stands in front of
// a box, an object's own patrol shows it from the time it detected it.
struct TimeWindow {
  TimestampNs first = std::numeric_limits<TimestampNs>::min(), last = std::numeric_limits<TimestampNs>::max();
};

// The kept frame that shows the box best, unoccluded (or in `window`, without a grid): most of its
// projection inside the image, near the centre, and large up to a quarter of the image (a close view, not one
// that fills the frame).
std::optional<Sighting> BestSighting(const PatrolRecord& record, const Eigen::Vector3d& low,
                                     const Eigen::Vector3d& high, const TimeWindow& window,
                                     const ReportOptions& options) {
  if (!record.camera.valid()) return std::nullopt;
  const std::array<Eigen::Vector3d, 8> corners = Corners(low, high);
  const Eigen::Vector3d centre = (low + high) / 2.0;
  const cv::Rect2d image(0, 0, record.camera.width, record.camera.height);
  const bool without_grid = record.grid.voxels.empty();
  std::optional<Sighting> best;
  double best_score = 0.0;
  for (const RouteFrame& frame : record.route) {
    if (without_grid && (frame.timestamp_ns < window.first || frame.timestamp_ns > window.last)) continue;
    if (!frame.pose || (frame.pose->position - centre).norm() > options.max_view_range_m) continue;
    const cv::Rect2d box = ProjectCorners(record.camera, *frame.pose, corners, record.distortion);
    if (box.area() <= 0.0) continue;
    const double inside = (box & image).area() / box.area();
    const cv::Point2d off((box.x + box.width / 2.0) / image.width - 0.5,
                          (box.y + box.height / 2.0) / image.height - 0.5);
    const double centred = 1.0 - std::min(1.0, std::hypot(off.x, off.y));  // room for context on every side
    const double score = inside * inside * centred * std::min(box.area() / image.area(), 0.25);
    if (inside < 0.5 || score <= best_score || Occluded(record.grid, frame.pose->position, low, high)) continue;
    best_score = score;
    best = Sighting{&frame, box};
  }
  return best;
}

cv::Mat Decode(const RouteFrame& frame) {
  if (frame.jpeg.empty()) return cv::Mat();
  return cv::imdecode(frame.jpeg, cv::IMREAD_COLOR);  // BGR, grey frames too
}

// The longer side scaled to `size` pixels.
cv::Mat Fit(const cv::Mat& image, int size, double* scale) {
  *scale = static_cast<double>(size) / std::max(image.cols, image.rows);
  cv::Mat out;
  cv::resize(image, out, cv::Size(), *scale, *scale, *scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

// The sighting's frame cropped around the box (with a margin), the box outlined.
ChangeView CropView(const std::string& flight, const PatrolRecord& record, const Sighting& sighting,
                    const ReportOptions& options) {
  ChangeView view{flight, sighting.frame->timestamp_ns, sighting.frame->frame_index, cv::Mat()};
  const cv::Mat frame = Decode(*sighting.frame);
  if (frame.empty()) return view;
  const double to_frame = static_cast<double>(frame.cols) / record.camera.width;
  const cv::Rect2d box(sighting.box.x * to_frame, sighting.box.y * to_frame, sighting.box.width * to_frame,
                       sighting.box.height * to_frame);
  const double margin = options.crop_margin * std::max({box.width, box.height, 16.0});
  const cv::Rect crop = cv::Rect(cv::Point(cvFloor(box.x - margin), cvFloor(box.y - margin)),
                                 cv::Point(cvCeil(box.br().x + margin), cvCeil(box.br().y + margin))) &
                        cv::Rect(0, 0, frame.cols, frame.rows);
  if (crop.area() <= 0) return view;
  double scale = 1.0;
  view.image = Fit(frame(crop), options.crop_size_px, &scale);
  const cv::Rect2d outline((box.x - crop.x) * scale, (box.y - crop.y) * scale, box.width * scale, box.height * scale);
  cv::rectangle(view.image, outline, kOutline, 2);
  return view;
}

// What `flight` saw of the box: its best kept frame, or no picture.
ChangeView ViewOfBox(const graph::TopoMap& map, const std::string& flight, const Eigen::Vector3d& low,
                     const Eigen::Vector3d& high, const TimeWindow& window, const ReportOptions& options) {
  const PatrolRecord* record = map.Patrol(flight);
  if (record == nullptr) return ChangeView{flight, 0, -1, cv::Mat()};
  std::optional<Sighting> sighting = BestSighting(*record, low, high, window, options);
  if (!sighting) sighting = BestSighting(*record, low, high, TimeWindow(), options);
  if (!sighting) return ChangeView{flight, 0, -1, cv::Mat()};
  return CropView(flight, *record, *sighting, options);
}

const MapObject* FindObject(const PatrolRecord* record, int id) {
  if (record == nullptr) return nullptr;
  const auto it =
      std::find_if(record->objects.begin(), record->objects.end(), [id](const MapObject& o) { return o.id == id; });
  return it == record->objects.end() ? nullptr : &*it;
}

// A whole frame with boxes (in pixels of a `reference_width` wide image) outlined, at most twice crop_size_px.
cv::Mat OutlinedFrame(const cv::Mat& frame, int reference_width, const std::vector<cv::Rect>& boxes,
                      const ReportOptions& options) {
  double scale = 1.0;
  cv::Mat image =
      Fit(frame, std::max(options.crop_size_px, std::min(2 * frame.cols, 2 * options.crop_size_px)), &scale);
  const double to_image = static_cast<double>(image.cols) / reference_width;
  for (const cv::Rect& b : boxes) {
    cv::rectangle(image, cv::Rect2d(b.x * to_image, b.y * to_image, b.width * to_image, b.height * to_image), kOutline,
                  2);
  }
  return image;
}

// The node's key frame with the regions outlined: the kept frame of the same frame index, else the thumbnail.
ChangeView KeyFramePicture(const graph::TopoMap& map, int node, const std::vector<cv::Rect>& boxes,
                           const ReportOptions& options) {
  const KeyFrameNode& n = map.node(node);
  ChangeView view{n.flight, n.timestamp_ns, n.frame_index, cv::Mat()};
  cv::Mat frame;
  const PatrolRecord* record = map.Patrol(n.flight);
  if (record != nullptr) {
    const auto kept = std::find_if(record->route.begin(), record->route.end(),
                                   [&n](const RouteFrame& f) { return f.frame_index == n.frame_index; });
    if (kept != record->route.end()) frame = Decode(*kept);
  }
  if (frame.empty() && !n.thumbnail.empty()) cv::cvtColor(n.thumbnail, frame, cv::COLOR_GRAY2BGR);
  if (frame.empty() || n.thumbnail.empty()) return view;
  view.image = OutlinedFrame(frame, n.thumbnail.cols, boxes, options);
  return view;
}

// A route frame with one region outlined (its box in the frame's pixels).
ChangeView RouteView(const std::string& flight, const RouteFrame& frame, const cv::Rect& box,
                     const ReportOptions& options) {
  ChangeView view{flight, frame.timestamp_ns, frame.frame_index, cv::Mat()};
  const cv::Mat image = Decode(frame);
  if (!image.empty()) view.image = OutlinedFrame(image, image.cols, {box}, options);
  return view;
}

// An appearance change's place: its point where it has one, its bearing from the camera otherwise.
void SetLocation(const ChangeLocation& location, const ReportOptions& options, ChangeItem* item) {
  item->located = ToString(location.by);
  item->channels = {"appearance"};
  if (location.HasPoint()) {
    item->position = location.point;
    item->extent = {Eigen::AlignedBox3d(location.point, location.point)};
  }
  if (location.by == LocatedBy::kNone) return;
  item->bearing = location.bearing;
  item->bearing_range_m = options.max_view_range_m;
}

bool Reported(ObjectState state) {
  return state == ObjectState::kNew || state == ObjectState::kRemoved || state == ObjectState::kMoved;
}

// A class-agnostic object's pictures: the extent of its changed voxels where it was and where it is (each side's
// extent for the patrol that lacks it), from any time of each patrol.
void AddClassAgnosticViews(const ChangeReport& report, const graph::TopoMap& map, const ObjectChange& o,
                           const ReportOptions& options, ChangeItem* item) {
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(report.geometry.voxel_size / 2.0);
  const Eigen::AlignedBox3d& then = o.box_before.isEmpty() ? o.box_after : o.box_before;
  const Eigen::AlignedBox3d& now = o.box_after.isEmpty() ? o.box_before : o.box_after;
  item->before = ViewOfBox(map, report.prior_flight, then.min() - half, then.max() + half, TimeWindow(), options);
  item->after = ViewOfBox(map, report.current_flight, now.min() - half, now.max() + half, TimeWindow(), options);
}

ChangeItem ObjectItem(const ChangeReport& report, const graph::TopoMap& map, const ObjectChange& o,
                      const ReportOptions& options) {
  ChangeItem item;
  item.id = ObjectChangeId(o);
  item.kind = "object";
  item.state = ToString(o.state);
  item.label = o.label;
  item.confidence = o.confidence;
  item.position = o.after ? o.after : o.before;
  if (o.state == ObjectState::kMoved) item.from = o.before;
  item.site_object = o.site_id;
  if (o.class_agnostic) {
    item.channels = {"geometry objects"};
    for (const Eigen::AlignedBox3d& box : {o.box_before, o.box_after}) {
      if (!box.isEmpty()) item.extent.push_back(box);
    }
    AddClassAgnosticViews(report, map, o, options, &item);
    return item;
  }
  item.channels = {"detections"};
  const MapObject* prior = FindObject(map.Patrol(report.prior_flight), o.prior_id);
  const MapObject* current = FindObject(map.Patrol(report.current_flight), o.current_id);
  for (const MapObject* object : {prior, current}) {
    if (object != nullptr) item.extent.emplace_back(object->box_min, object->box_max);
  }
  // New: where it is now, then and now; removed: where it was; moved: each where it was seen. A patrol
  // that detected the object shows it from a frame of the time it did.
  const MapObject* then = prior != nullptr ? prior : current;
  const MapObject* now = current != nullptr ? current : prior;
  const auto seen = [](const MapObject* o) { return TimeWindow{o->first_seen_ns, o->last_seen_ns}; };
  if (then != nullptr) {
    item.before = ViewOfBox(map, report.prior_flight, then->box_min, then->box_max,
                            prior != nullptr ? seen(prior) : TimeWindow(), options);
  }
  if (now != nullptr) {
    item.after = ViewOfBox(map, report.current_flight, now->box_min, now->box_max,
                           current != nullptr ? seen(current) : TimeWindow(), options);
  }
  return item;
}

ChangeItem GeometryItem(const ChangeReport& report, const graph::TopoMap& map, const GeometryRegion& r,
                        const ReportOptions& options) {
  ChangeItem item;
  item.id = GeometryChangeId(r.centroid);
  item.kind = "geometry";
  item.state = r.appeared >= r.vanished ? "appeared" : "vanished";
  item.label = std::to_string(r.voxels) + " voxels";
  item.confidence = std::clamp(r.score, 0.0, 1.0);
  item.position = r.centroid;
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(report.geometry.voxel_size / 2.0);
  item.channels = {"geometry"};
  item.extent = {Eigen::AlignedBox3d(r.box_min - half, r.box_max + half)};
  item.before = ViewOfBox(map, report.prior_flight, r.box_min - half, r.box_max + half, TimeWindow(), options);
  item.after = ViewOfBox(map, report.current_flight, r.box_min - half, r.box_max + half, TimeWindow(), options);
  return item;
}

ChangeItem AppearanceItem(const graph::TopoMap& map, const PlaceChange& place, const ReportOptions& options) {
  ChangeItem item;
  item.id = AppearanceChangeId(place.prior_node, place.current_node);
  item.kind = "appearance";
  item.state = "changed";
  const std::size_t regions = place.appearance.regions.size();
  item.label = std::to_string(regions) + (regions == 1 ? " region" : " regions");
  item.confidence = std::clamp(place.appearance.regions[0].score, 0.0, 1.0);
  SetLocation(place.location, options, &item);
  std::vector<cv::Rect> prior_boxes, current_boxes;
  for (const AppearanceRegion& r : place.appearance.regions) {
    prior_boxes.push_back(r.prior_box);
    current_boxes.push_back(r.current_box);
  }
  item.before = KeyFramePicture(map, place.prior_node, prior_boxes, options);
  item.after = KeyFramePicture(map, place.current_node, current_boxes, options);
  return item;
}

// A change found along the route: its best view's two route frames, the region outlined.
ChangeItem RouteItem(const ChangeReport& report, const graph::TopoMap& map, const RouteChange& change,
                     const ReportOptions& options) {
  const RouteChange::View& best = change.views[change.best];
  const RoutePair& pair = report.route.pairs[best.pair];
  const AppearanceRegion& region = pair.appearance.regions[best.region];
  const RouteFrame& prior = map.Patrol(report.prior_flight)->route[pair.prior];
  const RouteFrame& current = map.Patrol(report.current_flight)->route[pair.current];
  ChangeItem item;
  item.id = RouteChangeId(prior, current);
  item.kind = "appearance";
  item.state = "changed";
  item.label = "seen in " + std::to_string(change.views.size()) + " views";
  if (change.marked_share > 0.0) {  // the inspector learns that the shape changed too, not only the look
    item.label += ", depth changed over " + std::to_string(static_cast<int>(std::lround(100.0 * change.marked_share))) +
                  " % of it";
  }
  item.confidence = change.confidence;
  SetLocation(change.location, options, &item);
  item.before = RouteView(report.prior_flight, prior, region.prior_box, options);
  item.after = RouteView(report.current_flight, current, region.current_box, options);
  return item;
}

Status WriteView(const ChangeView& view, const std::string& path) {
  std::vector<unsigned char> jpeg;
  if (!cv::imencode(".jpg", view.image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 85}))
    return Status::IoError(path + ": cannot encode the picture");
  return WriteFileAtomically(path, std::string(jpeg.begin(), jpeg.end()));
}

}  // namespace

int ChangeReport::ChangedPlaces() const {
  return static_cast<int>(
      std::count_if(places.begin(), places.end(), [](const PlaceChange& p) { return !p.appearance.regions.empty(); }));
}

int ChangeReport::ObjectsIn(ObjectState state) const {
  return static_cast<int>(
      std::count_if(objects.begin(), objects.end(), [state](const ObjectChange& o) { return o.state == state; }));
}

namespace {

// "<x>_<y>_<z>": the 2 m cell of a position.
std::string CellName(const Eigen::Vector3d& position) {
  const Eigen::Vector3d cell = (position / kRegionCellM).array().floor();
  return std::to_string(static_cast<long long>(cell.x())) + "_" + std::to_string(static_cast<long long>(cell.y())) +
         "_" + std::to_string(static_cast<long long>(cell.z()));
}

}  // namespace

std::string ObjectChangeId(const ObjectChange& change) {
  if (change.class_agnostic) {
    const std::optional<Eigen::Vector3d>& where = change.after ? change.after : change.before;
    return "object-g" + CellName(where.value_or(Eigen::Vector3d::Zero()));
  }
  return "object-p" + std::to_string(change.prior_id) + "-c" + std::to_string(change.current_id);
}

std::string GeometryChangeId(const Eigen::Vector3d& centroid) { return "geometry-" + CellName(centroid); }

std::string AppearanceChangeId(int prior_node, int current_node) {
  return "appearance-" + std::to_string(prior_node) + "-" + std::to_string(current_node);
}

std::string RouteChangeId(const RouteFrame& prior, const RouteFrame& current) {
  return "appearance-f" + std::to_string(prior.frame_index) + "-" + std::to_string(current.frame_index);
}

namespace {

// ChangeItem::compared_in_3d.
std::optional<bool> ComparedIn3d(const ChangeReport& report, const ChangeItem& item) {
  if (!report.geometry_compared || report.geometry.poses_disagree) return std::nullopt;
  for (const std::string& channel : item.channels) {
    if (channel == "geometry" || channel == "geometry objects") return true;
  }
  if (!item.position) return std::nullopt;
  return report.geometry.ComparedNear(*item.position) && (!item.from || report.geometry.ComparedNear(*item.from));
}

}  // namespace

std::vector<ChangeItem> ReportItems(const ChangeReport& report, const graph::TopoMap& map,
                                    const ReportOptions& options) {
  std::vector<ChangeItem> items;
  const auto add = [&items](ChangeItem item, const char* list, std::size_t index) {
    item.source = {list, static_cast<int>(index)};
    items.push_back(std::move(item));
  };
  for (std::size_t i = 0; i < report.objects.size(); ++i) {
    if (Reported(report.objects[i].state)) add(ObjectItem(report, map, report.objects[i], options), "objects", i);
  }
  for (std::size_t i = 0; i < report.geometry.regions.size(); ++i) {
    add(GeometryItem(report, map, report.geometry.regions[i], options), "geometry", i);
  }
  for (std::size_t i = 0; i < report.places.size(); ++i) {
    if (!report.places[i].appearance.regions.empty()) add(AppearanceItem(map, report.places[i], options), "places", i);
  }
  for (std::size_t i = 0; i < report.route.changes.size(); ++i) {
    add(RouteItem(report, map, report.route.changes[i], options), "route", i);
  }
  // Regions in one 2 m cell share their id (one onboard event each); in the report the later ones get "-2", ...
  std::map<std::string, int> seen;
  for (ChangeItem& item : items) {
    const int repeat = ++seen[item.id];
    if (repeat > 1) item.id += "-" + std::to_string(repeat);
  }
  items = FuseItems(std::move(items), options.fuse_distance_m);
  for (std::size_t i = 0; i < items.size(); ++i) {
    items[i].number = static_cast<int>(i) + 1;
    items[i].compared_in_3d = ComparedIn3d(report, items[i]);
  }
  return items;
}

Eigen::Vector3d BearingEnd(const ChangeItem& item) {
  return item.bearing->origin + item.bearing_range_m * item.bearing->direction;
}

std::string ViewFileName(const ChangeItem& item, bool before) {
  return item.id + (before ? "-before.jpg" : "-after.jpg");
}

Status WriteChangeReport(const ChangeReport& report, const graph::TopoMap& map, const std::string& folder,
                         std::vector<ChangeItem>* written) {
  constexpr char kImages[] = "changes_images";
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  const std::vector<ChangeItem> items = ReportItems(report, map);
  if (!items.empty()) PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder + "/" + kImages));
  for (const ChangeItem& item : items) {
    for (const bool before : {true, false}) {
      const ChangeView& view = before ? item.before : item.after;
      if (view.image.empty()) continue;
      PATROLMAP_RETURN_IF_ERROR(WriteView(view, folder + "/" + kImages + "/" + ViewFileName(item, before)));
    }
  }
  const PatrolRecord* current = map.Patrol(report.current_flight);
  const std::optional<GeoReference> geo = current != nullptr ? FitGeoReference(*current) : std::nullopt;
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/changes.json", ToJson(report, map, items, geo, kImages)));
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/changes.html", ToHtml(report, map, items, geo, kImages)));
  if (geo) {
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/changes.geojson", ToGeoJson(report, map, items, *geo)));
    PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/changes.kml", ToKml(report, map, items, *geo, kImages)));
  }
  if (written != nullptr) *written = items;
  return Status::Ok();
}

}  // namespace patrolmap::change
