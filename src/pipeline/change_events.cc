#include "patrolmap/pipeline/change_events.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "patrolmap/change/site_state.h"
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

// An appearance change's place: its point, and the bearing from the camera it lies on.
void Locate(const change::ChangeLocation& location, Event* event) {
  if (location.HasPoint()) event->position = location.point;
  event->details["located"] = change::ToString(location.by);
  if (location.by == change::LocatedBy::kNone) return;
  event->details["bearing"] = {{"origin", Position(location.bearing.origin)},
                               {"direction", Position(location.bearing.direction)}};
}

Event AppearanceEvent(int prior_node, int node, TimestampNs timestamp_ns, const change::ChangeLocation& location,
                      const change::AppearanceChange& appearance) {
  Event event;
  event.id = change::AppearanceChangeId(prior_node, node);
  event.type = "appearance";
  event.timestamp_ns = timestamp_ns;
  event.confidence = std::min(1.0, appearance.regions.front().score);
  event.details = {{"node", node}, {"prior_node", prior_node}, {"regions", appearance.regions.size()}};
  Locate(location, &event);
  return event;
}

// A change found along the route, at the time of its best view's current frame, where it stands.
Event RouteEvent(const change::RouteChange& change, const change::ChangeReport& report, const graph::TopoMap& map) {
  const change::RoutePair& pair = report.route.pairs[change.views[change.best].pair];
  const RouteFrame& prior = map.Patrol(report.prior_flight)->route[pair.prior];
  const RouteFrame& current = map.Patrol(report.current_flight)->route[pair.current];
  Event event;
  event.id = change::RouteChangeId(prior, current);
  event.type = "appearance";
  event.timestamp_ns = current.timestamp_ns;
  event.confidence = change.confidence;
  event.details = {{"prior_frame", prior.frame_index}, {"frame", current.frame_index}, {"views", change.views.size()}};
  Locate(change.location, &event);
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
  if (prior_record_ == nullptr) return;
  // The same reference the final report compares with (CompareFlights): the site's latest state.
  std::vector<change::GridSource> sources;
  reference_ = change::LatestState(*prior, *prior_record_, &sources);
  prior_record_ = &reference_;
  change::ChangeOptions live = ChangeOptionsOf(config);
  live.geometry.min_observations = options.min_observations;
  detector_.emplace(*prior_record_, live);
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

void ChangeMonitor::OnNode(const KeyFrameNode& node, int feature_width, const std::optional<CameraPoseSample>& pose,
                           const MapLoopClosure* closure, const io::LogInfo& info) {
  if (closure == nullptr || closure->matched_node >= prior_->node_count()) return;
  const KeyFrameNode& before = prior_->node(closure->matched_node);
  if (before.flight != prior_flight_) return;
  if (!detector_) return;
  const change::AppearanceChange appearance = detector_->ComparePlace(
      change::KeyFrameOf(before.thumbnail, before.points, before.descriptors, prior_record_->feature_image_width),
      change::KeyFrameOf(node.thumbnail, node.points, node.descriptors, feature_width));
  if (appearance.regions.empty()) return;
  // A bearing only: the grid belongs to the change thread.
  const change::ChangeLocation location = change::BearingOfLargest(appearance, info.camera.value_or(CameraIntrinsics()),
                                                                   info.camera_distortion, node.thumbnail.cols, pose);
  Event event = AppearanceEvent(closure->matched_node, closure->query_node, node.timestamp_ns, location, appearance);
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
  const std::string flight = now.flight;
  const change::LiveFindings found = detector_->Check(std::move(now), recorder.grid());
  if (found.shift_changed) {
    spdlog::info("{}: compared while flying, {}", flight,
                 change::DescribeShift(found.search, recorder.grid()->voxel_size(), prior_flight_));
  }
  if (found.held != change::HoldReason::kNone) {
    WarnHeldBack(flight, found);
    seen_before_.clear();
    return;
  }
  std::vector<Event> candidates;
  for (const change::ObjectChange& change : found.objects) {
    if (Reported(change.state)) candidates.push_back(ObjectEvent(change, timestamp_ns));
  }
  if (found.geometry_compared) {
    for (const change::GeometryRegion& region : found.geometry.regions) {
      candidates.push_back(GeometryEvent(region, timestamp_ns));
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

void ChangeMonitor::WarnHeldBack(const std::string& flight, const change::LiveFindings& found) {
  if (found.held == change::HoldReason::kPosesDisagree && !warned_poses_) {
    // The objects are placed by the same poses (change_detector.h): nothing is sent while they disagree.
    spdlog::warn(
        "{}: its surfaces differ from {}'s in {:.0f} % of the voxels both observed: the camera poses "
        "disagree (GPS without RTK, or another world frame), so no geometry or object change is sent "
        "while they do",
        flight, prior_flight_, 100.0 * found.geometry.DifferingShare());
    warned_poses_ = true;
  }
  if (found.held == change::HoldReason::kUndecidedShift && !warned_undecided_) {
    // What differs may be a shift the grid built so far cannot yet tell (a few facades over much flat ground).
    const Eigen::Vector3d m = found.search.best.cast<double>() * prior_record_->grid.voxel_size;
    spdlog::info(
        "{}: moved by ({:.2f}, {:.2f}, {:.2f}) m its surfaces meet {}'s better than where they are, but not yet by "
        "change.alignment.min_gain: no geometry or object change is sent until the shift is taken or no longer fits "
        "better",
        flight, m.x(), m.y(), m.z(), prior_flight_);
    warned_undecided_ = true;
  }
}

Status ChangeMonitor::Close(const change::ChangeReport& report, const graph::TopoMap& map,
                            const std::vector<change::ChangeItem>& entries) {
  std::map<std::string, std::string> entry_of;  // a finding's id: the entry that holds it
  for (const change::ChangeItem& entry : entries) {
    entry_of[entry.id] = entry.id;
    for (const change::ChangeEvidence& e : entry.evidence) entry_of[e.id] = entry.id;
  }
  // The ids the report gives (a later region in the same 2 m cell, or a route change with the same best frames,
  // has "-2" appended there).
  const std::vector<std::string> route_ids = change::IdsOf(entries, "route", report.route.changes.size());
  const std::vector<std::string> region_ids = change::IdsOf(entries, "geometry", report.geometry.regions.size());
  const auto send = [&](Event event, const std::string& report_id = std::string()) {
    if (!report_id.empty()) event.id = report_id;
    const auto entry = entry_of.find(event.id);
    if (entry != entry_of.end()) event.details["entry"] = entry->second;
    Send(event, true);
  };
  for (const change::PlaceChange& place : report.places) {
    if (place.appearance.regions.empty()) continue;
    const TimestampNs t = map.node(place.current_node).timestamp_ns;
    send(AppearanceEvent(place.prior_node, place.current_node, t, place.location, place.appearance));
  }
  for (std::size_t i = 0; i < report.route.changes.size(); ++i) {
    send(RouteEvent(report.route.changes[i], report, map), route_ids[i]);
  }
  const TimestampNs end_ns = last_ns_;
  for (const change::ObjectChange& change : report.objects) {
    if (Reported(change.state)) send(ObjectEvent(change, end_ns));
  }
  for (std::size_t i = 0; i < report.geometry.regions.size(); ++i) {
    send(GeometryEvent(report.geometry.regions[i], end_ns), region_ids[i]);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (status_.ok() && ::fsync(fd_) != 0) status_ = Status::IoError(path_ + ": " + std::strerror(errno));
  return status_;
}

}  // namespace patrolmap::pipeline
