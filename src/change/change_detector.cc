#include "patrolmap/change/change_detector.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "patrolmap/change/geometry_objects.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/route_compare.h"

namespace patrolmap::change {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool AlongRoute(const PatrolRecord& prior, const PatrolRecord& current, const RouteCompareOptions& options) {
  return options.enabled && !prior.route.empty() && !current.route.empty();
}

}  // namespace

KeyFrameView KeyFrameOf(const cv::Mat& thumbnail, std::vector<cv::Point2f> points, cv::Mat descriptors,
                        int feature_width) {
  KeyFrameView view;
  view.image = thumbnail;
  view.points = std::move(points);
  view.descriptors = std::move(descriptors);
  if (feature_width > 0 && !thumbnail.empty()) view.feature_scale = static_cast<double>(feature_width) / thumbnail.cols;
  return view;
}

ChangeDetector::ChangeDetector(const PatrolRecord& prior, const ChangeOptions& options)
    : prior_(prior), options_(options) {}

GridShift ChangeDetector::Align(PatrolRecord* current) const {
  if (prior_.grid.voxels.empty() || current->grid.voxels.empty()) return GridShift();
  const GridShift shift = FindGridShift(prior_.grid, current->grid, options_.alignment);
  if (shift.applied) ShiftRecord(shift.voxels, current);
  return shift;
}

void ChangeDetector::FindObjects(const PatrolRecord& current, const GeometryChange& geometry, bool geometry_compared,
                                 const VoxelLookup& current_grid, std::vector<ObjectChange>* objects, bool* compared,
                                 double* seconds_detected) const {
  if (prior_.has_objects && current.has_objects) {
    const auto start = std::chrono::steady_clock::now();
    *objects = DiffObjects(prior_, current, options_.objects);
    *compared = true;
    if (seconds_detected != nullptr) *seconds_detected = SecondsSince(start);
  }
  if (geometry_compared && options_.geometry_objects.enabled) {
    const std::vector<ObjectChange> clusters =
        GeometryObjects(geometry, LookupIn(prior_.grid), current_grid, prior_.objects, current.objects,
                        ForPoseSources(options_.geometry_objects, prior_.pose_source, current.pose_source));
    objects->insert(objects->end(), clusters.begin(), clusters.end());
    *compared = true;
  }
}

void ChangeDetector::Compare(const PatrolRecord& current, const std::vector<PlacePair>& places,
                             ChangeReport* report) const {
  *report = ChangeReport();
  report->prior_flight = prior_.flight;
  report->current_flight = current.flight;
  auto start = std::chrono::steady_clock::now();
  const bool along_route = AlongRoute(prior_, current, options_.route);
  std::vector<RouteAnchor> anchors;
  for (const PlacePair& pair : places) {
    PlaceChange place;
    place.prior_node = pair.prior_node, place.current_node = pair.current_node;
    anchors.push_back({pair.prior_ns, pair.current_ns});
    if (!along_route) place.appearance = ComparePlace(pair.prior, pair.current);
    place.location = BearingOfLargest(place.appearance, current.camera, current.distortion, pair.current.image.cols,
                                      pair.current_pose);
    OnGrid(current.grid, &place.location);
    report->places.push_back(std::move(place));
  }
  if (along_route) {
    report->route = CompareRoutes(prior_.route, current.route, anchors, options_.route, options_.appearance,
                                  RouteCamerasOf(prior_, current), options_.location);
    for (RouteChange& change : report->route.changes) OnGrid(current.grid, &change.location);
  }
  report->seconds_appearance = SecondsSince(start);
  report->pose_prior = prior_.pose_source;
  report->pose_current = current.pose_source;

  start = std::chrono::steady_clock::now();
  report->geometry_compared =
      DiffGrids(prior_.grid, current.grid, ForPoseSources(options_.geometry, prior_.pose_source, current.pose_source),
                &report->geometry);
  report->geometry.depth_prior = prior_.depth_source;
  report->geometry.depth_current = current.depth_source;
  // Objects are placed by the same poses as the grids: where those disagree, their comparison would be as wrong.
  if (report->geometry.poses_disagree) {
    report->seconds_geometry = SecondsSince(start);
    return;
  }
  FindObjects(current, report->geometry, report->geometry_compared, LookupIn(current.grid), &report->objects,
              &report->objects_compared, &report->seconds_objects);
  report->seconds_geometry = SecondsSince(start) - report->seconds_objects;
}

void ChangeDetector::OnGrid(const EvidenceGridData& grid, ChangeLocation* location) const {
  if (location->by == LocatedBy::kNone || location->by == LocatedBy::kDepth || grid.voxels.empty()) return;
  const std::optional<Eigen::Vector3d> surface =
      FirstSurface(LookupIn(grid), grid.voxel_size, location->bearing, options_.location);
  if (!surface) return;
  location->by = LocatedBy::kGrid;
  location->point = *surface;
}

AppearanceChange ChangeDetector::ComparePlace(const KeyFrameView& prior, const KeyFrameView& current) const {
  return DetectAppearanceChange(prior, current, options_.appearance);
}

LiveFindings ChangeDetector::Check(PatrolRecord now, const EvidenceGrid* grid) {
  LiveFindings found;
  const GeometryDiffOptions diff = ForPoseSources(options_.geometry, prior_.pose_source, now.pose_source);
  found.geometry_compared =
      grid != nullptr && prior_.grid.voxel_size > 0 && DiffGrids(prior_.grid, *grid, diff, &found.geometry, shift_);
  // More differs than right poses give while no shift is taken, or the poses disagree again: a shift is searched.
  const bool search =
      found.geometry.poses_disagree ||
      (shift_ == Eigen::Vector3i::Zero() && found.geometry.DifferingShare() > options_.alignment.min_differing_share);
  if (found.geometry_compared && search) {
    if (!shift_search_) shift_search_.emplace(prior_.grid, options_.alignment);
    found.search = shift_search_->Find(*grid);
    if (found.search.applied && found.search.voxels != shift_) {
      shift_ = found.search.voxels;
      found.shift_changed = true;
      DiffGrids(prior_.grid, *grid, diff, &found.geometry, shift_);
    }
  }
  if (found.geometry.poses_disagree) found.held = HoldReason::kPosesDisagree;
  if (!found.geometry.poses_disagree && found.search.Undecided()) found.held = HoldReason::kUndecidedShift;
  if (found.held != HoldReason::kNone) return found;
  if (grid != nullptr && shift_ != Eigen::Vector3i::Zero()) {
    MoveRecordPoses(shift_.cast<double>() * grid->voxel_size(), &now);
  }
  bool objects_compared = false;
  FindObjects(now, found.geometry, found.geometry_compared, grid != nullptr ? LookupIn(*grid, shift_) : VoxelLookup(),
              &found.objects, &objects_compared, nullptr);
  return found;
}

}  // namespace patrolmap::change
