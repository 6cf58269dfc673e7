#include "patrolmap/pipeline/change_events.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/geometry_objects.h"
#include "patrolmap/change/grid_alignment.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/core/option_check.h"

namespace patrolmap::pipeline {

using nlohmann::json;

struct ChangeMonitor::Event {
  std::string id, type;
  TimestampNs timestamp_ns = 0;
  std::optional<Eigen::Vector3d> position;
  double confidence = 0.0;
  json details = json::object();
};

namespace {

using Event = ChangeMonitor::Event;

json Position(const Eigen::Vector3d& p) { return json::array({p.x(), p.y(), p.z()}); }

bool Reported(change::ObjectState state) {
  return state == change::ObjectState::kNew || state == change::ObjectState::kRemoved ||
         state == change::ObjectState::kMoved;
}

// The key frame of a node as the appearance comparison needs it (as pipeline::CompareFlights builds it).
change::KeyFrameView ViewOf(const cv::Mat& thumbnail, std::vector<cv::Point2f> points, cv::Mat descriptors,
                            int feature_width) {
  change::KeyFrameView view;
  view.image = thumbnail;
  view.points = std::move(points);
  view.descriptors = std::move(descriptors);
  if (feature_width > 0 && !thumbnail.empty()) view.feature_scale = static_cast<double>(feature_width) / thumbnail.cols;
  return view;
}

Event ObjectEvent(const change::ObjectChange& change, TimestampNs timestamp_ns) {
  Event event;
  event.id = change::ObjectChangeId(change);
  event.type = std::string("object_") + change::ToString(change.state);
  event.timestamp_ns = timestamp_ns;
  event.position = change.after ? change.after : change.before;
  event.confidence = change.confidence;
  event.details = {{"label", change.label}, {"source", change.class_agnostic ? "geometry" : "detections"}};
  return event;
}

Event GeometryEvent(const change::GeometryRegion& region, TimestampNs timestamp_ns) {
  Event event;
  event.id = change::GeometryChangeId(region.centroid);
  event.type = "geometry";
  event.timestamp_ns = timestamp_ns;
  event.position = region.centroid;
  event.confidence = std::min(1.0, region.score);
  event.details = {{"voxels", region.voxels}, {"appeared", region.appeared}, {"vanished", region.vanished}};
  return event;
}

Event AppearanceEvent(int prior_node, int node, TimestampNs timestamp_ns,
                      const std::optional<Eigen::Vector3d>& position, const change::AppearanceChange& appearance) {
  Event event;
  event.id = change::AppearanceChangeId(prior_node, node);
  event.type = "appearance";
  event.timestamp_ns = timestamp_ns;
  event.position = position;
  event.confidence = std::min(1.0, appearance.regions.front().score);
  event.details = {{"node", node}, {"prior_node", prior_node}, {"regions", appearance.regions.size()}};
  return event;
}

// A change found along the route, at the time and camera position of its best view's current frame.
Event RouteEvent(const change::RouteChange& change, const change::ChangeReport& report, const graph::TopoMap& map) {
  const change::RoutePair& pair = report.route.pairs[change.views[change.best].pair];
  const RouteFrame& prior = map.Patrol(report.prior_flight)->route[pair.prior];
  const RouteFrame& current = map.Patrol(report.current_flight)->route[pair.current];
  Event event;
  event.id = change::RouteChangeId(prior, current);
  event.type = "appearance";
  event.timestamp_ns = current.timestamp_ns;
  if (current.pose) event.position = current.pose->position;
  event.confidence = change.confidence;
  event.details = {{"prior_frame", prior.frame_index}, {"frame", current.frame_index}, {"views", change.views.size()}};
  if (current.gps) event.details["gps"] = json::array({current.gps->x(), current.gps->y()});
  return event;
}

}  // namespace

bool ChangeEventOptions::IsValid(std::string* error) const {
  return OptionCheck(error)
      .AboveAtMost("events interval (--events-interval-s)", interval_s, 0.0, 3600.0)
      .InRange("events settle time (--events-settle-s)", settle_s, 0.0, 3600.0)
      .InRange("events' rays per voxel (--events-min-observations)", min_observations, 1, 65535)
      .ok();
}

Status ChangeMonitor::Open(const graph::TopoMap* prior, const std::string& prior_flight, const Config& config,
                           const ChangeEventOptions& options, const std::string& path,
                           std::unique_ptr<ChangeMonitor>* monitor) {
  std::string error;
  if (!options.IsValid(&error)) return Status::InvalidArgument(error);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return Status::IoError(path + ": cannot open for appending: " + std::strerror(errno));
  monitor->reset(new ChangeMonitor(prior, prior_flight, config, options, fd));
  (*monitor)->path_ = path;
  return Status::Ok();
}

ChangeMonitor::ChangeMonitor(const graph::TopoMap* prior, const std::string& prior_flight, const Config& config,
                             const ChangeEventOptions& options, int fd)
    : prior_(prior),
      prior_flight_(prior_flight),
      prior_record_(prior->Patrol(prior_flight)),
      config_(config),
      options_(options),
      fd_(fd) {
  check_geometry_ = config.change.geometry;
  check_geometry_.min_observations = options.min_observations;
}

ChangeMonitor::~ChangeMonitor() { ::close(fd_); }

int ChangeMonitor::events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

void ChangeMonitor::Send(const Event& event, bool final_event) {
  json line = {{"id", event.id},
               {"type", event.type},
               {"time_ns", event.timestamp_ns},
               {"position", event.position ? Position(*event.position) : json(nullptr)},
               {"confidence", event.confidence}};
  line.update(event.details);
  if (final_event) line["final"] = true;
  const std::string text = line.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  if (!sent_.insert(event.id).second || !status_.ok()) return;
  // One write() a line: whole or not at all, even if the process dies now.
  const ssize_t written = ::write(fd_, text.data(), text.size());
  if (written != static_cast<ssize_t>(text.size())) {
    status_ = Status::IoError(path_ + ": cannot append an event: " + std::strerror(errno));
    return;
  }
  ++events_;
}

void ChangeMonitor::OnNode(const MapNode& node, const std::optional<CameraPoseSample>& pose,
                           const MapLoopClosure* closure, const place::PlaceRecognizer& recognizer) {
  if (pose) node_positions_[node.node] = pose->position;
  if (closure == nullptr || closure->matched_node >= prior_->node_count()) return;
  const graph::NodeData& before = prior_->node(closure->matched_node);
  if (before.flight != prior_flight_) return;
  place::PlaceRecognizer::NodeFeatures features = recognizer.Features(node.node);
  const change::AppearanceChange appearance = change::DetectAppearanceChange(
      ViewOf(before.thumbnail, before.points, before.descriptors,
             prior_record_ != nullptr ? prior_record_->feature_image_width : 0),
      ViewOf(node.thumbnail, std::move(features.points), std::move(features.descriptors), node.feature_width),
      config_.change.appearance);
  if (appearance.regions.empty()) return;
  Event event = AppearanceEvent(closure->matched_node, node.node, node.timestamp_ns,
                                pose ? std::optional<Eigen::Vector3d>(pose->position) : std::nullopt, appearance);
  if (node.gps) event.details["gps"] = json::array({node.gps->x(), node.gps->y()});
  Send(event, false);
}

void ChangeMonitor::OnChangeStep(TimestampNs timestamp_ns, const PatrolRecorder& recorder) {
  if (prior_record_ == nullptr) return;
  last_ns_ = std::max(last_ns_, timestamp_ns);
  if (!started_) {
    started_ = true;
    first_ns_ = timestamp_ns;
    next_check_ns_ = timestamp_ns + SecondsToNs(options_.interval_s);
  }
  if (timestamp_ns < next_check_ns_) return;
  next_check_ns_ = timestamp_ns + SecondsToNs(options_.interval_s);
  CheckRecord(timestamp_ns, recorder);
}

void ChangeMonitor::CheckRecord(TimestampNs timestamp_ns, const PatrolRecorder& recorder) {
  // The grid is compared where it is built: a copy of it each check (1.2 million voxels after an hour, 19 MB,
  // sorted) was the onboard run's memory peak.
  PatrolRecord now = recorder.Snapshot(timestamp_ns - SecondsToNs(options_.settle_s), false);
  const change::EvidenceGrid* grid = recorder.grid();
  std::vector<Event> candidates;
  change::GeometryChange geometry;
  const change::GeometryDiffOptions diff =
      change::ForPoseSources(check_geometry_, prior_record_->pose_source, now.pose_source);
  const bool compared = prior_record_->grid.voxel_size > 0 && grid != nullptr &&
                        change::DiffGrids(prior_record_->grid, *grid, diff, &geometry, shift_);
  // More differs than right poses give while no shift is taken, or the poses disagree again: a shift is searched.
  const bool search =
      geometry.poses_disagree ||
      (shift_ == Eigen::Vector3i::Zero() && geometry.DifferingShare() > config_.change.alignment.min_differing_share);
  change::GridShift found;
  if (compared && search) {
    const Eigen::Vector3i before = shift_;
    found = Realign(now.flight, *grid);
    if (shift_ != before) change::DiffGrids(prior_record_->grid, *grid, diff, &geometry, shift_);
  }
  if (HoldBack(now.flight, geometry, found)) {
    seen_before_.clear();
    return;
  }
  if (shift_ != Eigen::Vector3i::Zero()) change::MoveRecordPoses(shift_.cast<double>() * grid->voxel_size(), &now);
  if (prior_record_->has_objects && now.has_objects) {
    for (const change::ObjectChange& change : change::DiffObjects(*prior_record_, now, config_.change.objects)) {
      if (Reported(change.state)) candidates.push_back(ObjectEvent(change, timestamp_ns));
    }
  }
  if (compared) {
    for (const change::GeometryRegion& region : geometry.regions) {
      candidates.push_back(GeometryEvent(region, timestamp_ns));
    }
    // Objects no detector named: clusters of the changed space (as the report finds them).
    for (const change::ObjectChange& change : change::GeometryObjects(
             geometry, change::LookupIn(prior_record_->grid), change::LookupIn(*grid, shift_), prior_record_->objects,
             now.objects,
             change::ForPoseSources(config_.change.geometry_objects, prior_record_->pose_source, now.pose_source))) {
      candidates.push_back(ObjectEvent(change, timestamp_ns));
    }
  }
  // A change is sent once two checks in a row found it: a region or object state of a grid or map still
  // being built at the camera's position often lasts one check only.
  std::set<std::string> seen;
  for (const Event& event : candidates) {
    seen.insert(event.id);
    if (seen_before_.count(event.id) != 0) Send(event, false);
  }
  seen_before_ = std::move(seen);
}

change::GridShift ChangeMonitor::Realign(const std::string& flight, const change::EvidenceGrid& grid) {
  if (!shift_search_) shift_search_.emplace(prior_record_->grid, config_.change.alignment);
  const change::GridShift found = shift_search_->Find(grid);
  if (found.applied && found.voxels != shift_) {
    shift_ = found.voxels;
    spdlog::info("{}: compared while flying, {}", flight,
                 change::DescribeShift(found, grid.voxel_size(), prior_flight_));
  }
  return found;
}

bool ChangeMonitor::HoldBack(const std::string& flight, const change::GeometryChange& geometry,
                             const change::GridShift& search) {
  if (geometry.poses_disagree) {
    // The objects are placed by the same poses (pipeline/change.cc): nothing is sent while they disagree.
    if (!warned_poses_) {
      spdlog::warn(
          "{}: its surfaces differ from {}'s in {:.0f} % of the voxels both observed: the camera poses "
          "disagree (GPS without RTK, or another world frame), so no geometry or object change is sent "
          "while they do",
          flight, prior_flight_, 100.0 * geometry.DifferingShare());
      warned_poses_ = true;
    }
    return true;
  }
  if (!search.Undecided()) return false;
  // What differs may be a shift the grid built so far cannot yet tell (a few facades over much flat ground).
  if (!warned_undecided_) {
    const Eigen::Vector3d m = search.best.cast<double>() * prior_record_->grid.voxel_size;
    spdlog::info(
        "{}: moved by ({:.2f}, {:.2f}, {:.2f}) m its surfaces meet {}'s better than where they are, but not yet by "
        "change.alignment.min_gain: no geometry or object change is sent until the shift is taken or no longer fits "
        "better",
        flight, m.x(), m.y(), m.z(), prior_flight_);
    warned_undecided_ = true;
  }
  return true;
}

Status ChangeMonitor::Close(const change::ChangeReport& report, const graph::TopoMap& map) {
  for (const change::PlaceChange& place : report.places) {
    if (place.appearance.regions.empty()) continue;
    const TimestampNs t = map.node(place.current_node).timestamp_ns;
    const auto at = node_positions_.find(place.current_node);
    const std::optional<Eigen::Vector3d> position =
        at == node_positions_.end() ? std::nullopt : std::optional<Eigen::Vector3d>(at->second);
    Send(AppearanceEvent(place.prior_node, place.current_node, t, position, place.appearance), true);
  }
  for (const change::RouteChange& change : report.route.changes) Send(RouteEvent(change, report, map), true);
  const TimestampNs end_ns = last_ns_;
  for (const change::ObjectChange& change : report.objects) {
    if (Reported(change.state)) Send(ObjectEvent(change, end_ns), true);
  }
  for (const change::GeometryRegion& region : report.geometry.regions) Send(GeometryEvent(region, end_ns), true);
  std::lock_guard<std::mutex> lock(mutex_);
  if (status_.ok() && ::fsync(fd_) != 0) status_ = Status::IoError(path_ + ": " + std::strerror(errno));
  return status_;
}

}  // namespace patrolmap::pipeline
