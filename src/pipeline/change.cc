#include "patrolmap/pipeline/change.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include <spdlog/spdlog.h>

#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/object_map.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"

namespace patrolmap::pipeline {
namespace {

constexpr double kViewRateHz = 5.0;  // views kept for visibility

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Reads a depth image; an unreadable one is reported, counted and left empty (the patrol goes on without it).
bool ReadDepthOrSkip(const std::string& path, cv::Mat* depth, PatrolRecordStats* stats) {
  const Status status = io::ReadDepthImage(path, depth);
  if (status.ok()) return true;
  spdlog::warn("{}; skipped", status.message());
  if (stats != nullptr) ++stats->skipped_depth_frames;
  depth->release();
  return false;
}

void SampleViews(const std::vector<CameraPoseSample>& poses, std::vector<CameraPoseSample>* views) {
  const TimestampNs step = SecondsToNs(1.0 / kViewRateHz);
  TimestampNs next = std::numeric_limits<TimestampNs>::min();
  for (const CameraPoseSample& pose : poses) {
    if (pose.timestamp_ns < next) continue;
    views->push_back(pose);
    next = pose.timestamp_ns + step;
  }
}

// The object map: the detections frame by frame, with the frame's depth and image when the log has them.
Status BuildObjectMap(const std::string& log, const io::PatrolSensors& sensors, const Config& config,
                      const std::vector<TimestampNs>& depth_times, PatrolRecord* record, PatrolRecordStats* stats,
                      const ChangeProgress& progress) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(log, config.input, &source));
  change::ObjectMapper mapper(config.change.object_map, record->camera);
  const std::vector<ObjectObservation>& all = sensors.detections;
  std::vector<ObjectObservation> frame_detections;
  std::size_t next = 0;
  Frame frame;
  cv::Mat depth;
  Status status;
  while (next < all.size() && (status = source->Next(true, &frame)).ok()) {
    while (next < all.size() && all[next].timestamp_ns < frame.timestamp_ns) ++next;  // no frame: dropped
    if (next == all.size() || all[next].timestamp_ns != frame.timestamp_ns) continue;
    frame_detections.clear();
    while (next < all.size() && all[next].timestamp_ns == frame.timestamp_ns) frame_detections.push_back(all[next++]);
    const std::optional<CameraPoseSample> pose = io::PoseAt(sensors.poses, frame.timestamp_ns);
    if (!pose) continue;
    depth.release();
    const auto depth_at = std::lower_bound(depth_times.begin(), depth_times.end(), frame.timestamp_ns);
    if (depth_at != depth_times.end() && *depth_at == frame.timestamp_ns) {
      ReadDepthOrSkip(sensors.depth[depth_at - depth_times.begin()].path, &depth, stats);
    }
    mapper.AddFrame(frame_detections, *pose, depth, frame.image);
    if (progress) progress(static_cast<std::int64_t>(next), static_cast<std::int64_t>(all.size()));
  }
  if (!status.ok() && !status.end_of_stream()) return status;
  record->objects = mapper.Finish();
  if (stats != nullptr) {
    stats->detections = static_cast<int>(all.size());
    stats->associations = mapper.associations();
    stats->association_seconds = mapper.association_seconds();
    stats->skipped_detections = mapper.skipped();
  }
  return Status::Ok();
}

Status BuildGrid(const io::PatrolSensors& sensors, const Config& config, PatrolRecord* record, PatrolRecordStats* stats,
                 const ChangeProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  change::EvidenceGrid grid(config.change.grid);
  const TimestampNs step = SecondsToNs(1.0 / config.change.grid.rate_hz);
  TimestampNs next = std::numeric_limits<TimestampNs>::min();
  cv::Mat depth;
  int frames = 0;
  for (std::size_t i = 0; i < sensors.depth.size(); ++i) {
    const io::DepthEntry& entry = sensors.depth[i];
    if (entry.timestamp_ns < next) continue;
    const std::optional<CameraPoseSample> pose = io::PoseAt(sensors.poses, entry.timestamp_ns);
    if (!pose) continue;
    if (!ReadDepthOrSkip(entry.path, &depth, stats)) continue;
    if (depth.cols != record->camera.width || depth.rows != record->camera.height) {
      spdlog::warn("{}: depth image is {}x{}, the camera {}x{}; skipped", entry.path, depth.cols, depth.rows,
                   record->camera.width, record->camera.height);
      if (stats != nullptr) ++stats->skipped_depth_frames;
      continue;
    }
    grid.Integrate(depth, record->camera, *pose);
    next = entry.timestamp_ns + step;
    ++frames;
    if (progress) progress(static_cast<std::int64_t>(i + 1), static_cast<std::int64_t>(sensors.depth.size()));
  }
  record->grid = grid.ToData();
  if (stats != nullptr) {
    stats->depth_frames = frames;
    stats->grid_seconds = SecondsSince(start);
    stats->dropped_voxel_updates = grid.dropped_updates();
  }
  return Status::Ok();
}

}  // namespace

Status BuildPatrolRecord(const std::string& log, const Config& config, PatrolRecord* record, PatrolRecordStats* stats,
                         const ChangeProgress& progress) {
  io::PatrolSensors sensors;
  PATROLMAP_RETURN_IF_ERROR(io::ReadPatrolSensors(log, &sensors));
  *record = PatrolRecord();
  record->flight = sensors.flight_id;
  if (sensors.camera) record->camera = *sensors.camera;
  if (sensors.poses.empty() || !sensors.camera) return Status::Ok();
  SampleViews(sensors.poses, &record->views);
  std::vector<TimestampNs> depth_times;
  for (const io::DepthEntry& entry : sensors.depth) depth_times.push_back(entry.timestamp_ns);
  if (!sensors.detections.empty()) {
    record->has_objects = true;
    PATROLMAP_RETURN_IF_ERROR(BuildObjectMap(log, sensors, config, depth_times, record, stats, progress));
  }
  if (!sensors.depth.empty()) PATROLMAP_RETURN_IF_ERROR(BuildGrid(sensors, config, record, stats, progress));
  return Status::Ok();
}

Status CompareFlights(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                      const change::ChangeOptions& options, change::ChangeReport* report) {
  const std::vector<std::string> flights = map.Flights();
  for (const std::string& flight : {prior, current}) {
    if (std::find(flights.begin(), flights.end(), flight) == flights.end()) {
      return Status::InvalidArgument("flight '" + flight + "' is not in the map");
    }
  }
  *report = change::ChangeReport();
  report->prior_flight = prior;
  report->current_flight = current;
  const PatrolRecord* prior_record = map.Patrol(prior);
  const PatrolRecord* current_record = map.Patrol(current);

  auto start = std::chrono::steady_clock::now();
  for (const graph::TopoMap::Edge& edge : map.Edges()) {
    if (edge.data.kind != graph::EdgeKind::kLoopClosure) continue;
    int a = edge.a, b = edge.b;
    if (map.node(a).flight == current) std::swap(a, b);
    if (map.node(a).flight != prior || map.node(b).flight != current) continue;
    const auto view = [&map](int node, const PatrolRecord* record) {
      const graph::NodeData& n = map.node(node);
      change::KeyFrameView v{n.thumbnail, n.keypoints, n.descriptors, 1.0};
      if (record != nullptr && record->feature_image_width > 0 && !n.thumbnail.empty()) {
        v.feature_scale = static_cast<double>(record->feature_image_width) / n.thumbnail.cols;
      }
      return v;
    };
    change::PlaceChange place;
    place.prior_node = a, place.current_node = b;
    place.appearance =
        change::DetectAppearanceChange(view(a, prior_record), view(b, current_record), options.appearance);
    report->places.push_back(std::move(place));
  }
  report->seconds_appearance = SecondsSince(start);
  if (prior_record == nullptr || current_record == nullptr) return Status::Ok();

  start = std::chrono::steady_clock::now();
  if (prior_record->has_objects && current_record->has_objects) {
    report->objects_compared = true;
    report->objects = change::DiffObjects(*prior_record, *current_record, options.objects);
  }
  report->seconds_objects = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  report->geometry_compared =
      change::DiffGrids(prior_record->grid, current_record->grid, options.geometry, &report->geometry);
  report->seconds_geometry = SecondsSince(start);
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
