// Wiring of a mapping run (mapping.h).
#include "patrolmap/pipeline/mapping.h"

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "patrolmap/change/change_detector.h"
#include "patrolmap/change/site_objects.h"
#include "patrolmap/change/site_state.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/flight_id.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/log_digest.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/change.h"
#include "patrolmap/pipeline/detect.h"

namespace patrolmap::pipeline {
namespace {

const char kCameraPrefix[] = "camera:";

bool IsCamera(const std::string& source) { return source.rfind(kCameraPrefix, 0) == 0; }

Status OpenSource(const std::string& spec, const io::ImageFolderOptions& options,
                  std::unique_ptr<io::FrameSource>* source) {
  if (!IsCamera(spec)) return io::OpenLog(spec, options, source);
  const std::string device = spec.substr(sizeof(kCameraPrefix) - 1);
  if (device.empty() || device.size() > 6 || !std::all_of(device.begin(), device.end(), ::isdigit)) {
    return Status::InvalidArgument(spec + ": expected camera:N with a device number N");
  }
  return io::OpenCamera(std::stoi(device), options, source);
}

// Everything the request names is checked before any work: a missing log first (the likeliest mistake), then
// outputs that would overwrite inputs, the options, the configuration.
Status CheckRequest(const MappingRequest& request, Config* config) {
  if (request.sources.empty()) return Status::InvalidArgument("no flight log given");
  for (const std::string& source : request.sources) {
    if (IsCamera(source)) continue;
    PATROLMAP_RETURN_IF_ERROR(io::CheckLogExists(source));
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInput(request.out, source, "flight log"));
  }
  const std::pair<std::string, const char*> inputs[] = {{request.prior_map, "prior map"},
                                                        {request.poses, "pose file"},
                                                        {request.camera, "camera file"},
                                                        {request.config_path, "configuration"},
                                                        {request.vocabulary_path, "vocabulary"}};
  for (const auto& [input, what] : inputs) {
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInFolder(request.out, input, what));
  }
  if (!request.flight_id.empty() && request.sources.size() > 1) {
    return Status::InvalidArgument("--flight-id " + request.flight_id + ": names one log; map the logs one at a time");
  }
  if (!request.flight_id.empty() && !IsValidFlightId(request.flight_id)) {
    return Status::InvalidArgument("--flight-id " + request.flight_id + ": a flight id is UTF-8 text of at most " +
                                   std::to_string(kMaxFlightIdLength) +
                                   " bytes without control characters, commas, quotes or slashes, not . or ..");
  }
  if (!request.poses.empty() && request.sources.size() > 1) {
    return Status::InvalidArgument("--poses " + request.poses +
                                   ": a pose file belongs to one log; map the logs "
                                   "one at a time (patrol adds each to the map)");
  }
  std::string error;
  if (!request.pass.IsValid(&error)) return Status::InvalidArgument(error);
  if (request.events && !request.events->IsValid(&error)) return Status::InvalidArgument(error);
  PATROLMAP_RETURN_IF_ERROR(LoadCheckedConfig(request.config_path, request.config_settings, config));
  if (request.fps > 0.0) config->input.frame_rate_hz = request.fps;
  PATROLMAP_RETURN_IF_ERROR(io::ParseTopicChoice(request.topics, &config->input.topics));
  return Status::Ok();
}

// What the patrol record of a flight holds, on the log.
void LogRecord(const FlightResult& flight) {
  const PatrolRecord& record = flight.record;
  const PatrolRecordStats& stats = flight.record_stats;
  if (record.has_objects) {
    const auto confirmed =
        std::count_if(record.objects.begin(), record.objects.end(), [](const MapObject& o) { return o.confirmed; });
    spdlog::info("{}: {} objects ({} more seen too rarely) from {} detections ({:.3f} ms per association)",
                 record.flight, confirmed, record.objects.size() - static_cast<std::size_t>(confirmed),
                 stats.detections, stats.associations ? 1e3 * stats.association_seconds / stats.associations : 0.0);
  }
  if (record.grid.voxel_size > 0) {
    spdlog::info("{}: evidence grid of {} voxels from {} depth frames in {:.1f} s{}", record.flight,
                 record.grid.voxels.size(), stats.depth_frames, stats.grid_seconds,
                 stats.stereo_pairs > 0
                     ? " (" + std::to_string(stats.stereo_pairs) + " stereo pairs matched, with the object map's)"
                     : std::string());
  }
  if (record.depth_source == kDepthFromFlight && stats.unpaired_frames > 0) {
    spdlog::info(
        "{}: depth from the flight: {} frames matched, {} without an earlier frame at least "
        "depth.flight.min_baseline_m "
        "away across the optical axis within depth.flight.history_s (the start, hovering, turning, or a camera "
        "looking along the flight)",
        record.flight, stats.flight_pairs, stats.unpaired_frames);
  }
}

// The plot's truth (when the log has it) and each key location's node id in nodes.csv.
PlotTruth FlightPlotTruth(const io::LogInfo& info, const FlightResult& flight, const MapResult& places) {
  PlotTruth truth = LoadPlotTruth(info.path, flight.detection.key_locations);
  for (const KeyLocation& key_location : flight.detection.key_locations) {
    const auto node = std::find_if(places.nodes.begin(), places.nodes.end(), [&](const KeyFrameNode& n) {
      return n.flight == info.flight_id && n.frame_index == key_location.frame_index;
    });
    truth.node_ids.push_back(
        node == places.nodes.end() ? -1 : places.first_node + static_cast<int>(node - places.nodes.begin()));
  }
  return truth;
}

Status WriteFlightOutputs(const MappingRequest& request, const io::LogInfo& info, const FlightResult& flight,
                          const MapResult& places) {
  switch (request.outputs) {
    case FlightOutputs::kDetection:
      return WriteDetectionOutputs(flight.detection,
                                   request.sources.size() > 1 ? request.out + "/" + info.flight_id : request.out,
                                   FlightPlotTruth(info, flight, places));
    case FlightOutputs::kKeyLocations:
      return WriteFileAtomically(request.out + "/key_locations.csv", KeyLocationsCsv(flight.detection.key_locations));
    case FlightOutputs::kNone: return Status::Ok();
  }
  return Status::Ok();
}

// The flights a new log must not repeat: the prior map's and those mapped earlier in this run.
struct KnownFlight {
  std::string id, source, digest;
};

std::vector<KnownFlight> KnownFlights(const graph::TopoMap& prior, const MappingOutcome& outcome) {
  std::vector<KnownFlight> known;
  for (const std::string& flight : prior.Flights()) {
    const PatrolRecord* record = prior.Patrol(flight);
    known.push_back({flight, record ? record->source : "", record ? record->source_digest : ""});
  }
  for (const FlightRun& run : outcome.flights) {
    const PatrolRecord& record = run.result.record;
    known.push_back({record.flight, record.source, record.source_digest});
  }
  return known;
}

// The flight id of a new log, its path and digest: a log whose content is already in the map is refused; an id
// the map has is refused when the user chose it, else the log's own id gets the first free suffix (ID-2, ID-3, ...,
// as merge --rename-clashes), with a warning, so two flights never become one.
Status IdentifyFlight(const std::string& spec, const std::string& chosen_id, const std::vector<KnownFlight>& known,
                      io::FrameSource* source, PatrolRecord* identity) {
  if (!IsCamera(spec)) {
    std::error_code ignored;
    const std::filesystem::path absolute = std::filesystem::absolute(spec, ignored).lexically_normal();
    identity->source = PrintableText(absolute.empty() ? spec : absolute.string());
    identity->source_digest = io::LogDigest(spec);
  }
  for (const KnownFlight& flight : known) {
    if (identity->source_digest.empty() || flight.digest != identity->source_digest) continue;
    return Status::InvalidArgument(spec + ": this log is already in the map as flight '" + flight.id + "'" +
                                   (flight.source.empty() ? "" : " (read from " + flight.source + ")") +
                                   "; a log is mapped once");
  }
  const auto taken = [&](const std::string& id) {
    return std::any_of(known.begin(), known.end(), [&](const KnownFlight& flight) { return flight.id == id; });
  };
  const std::string wanted = chosen_id.empty() ? source->info().flight_id : chosen_id;
  std::string id = wanted;
  if (taken(id) && !chosen_id.empty()) {
    return Status::InvalidArgument("--flight-id " + chosen_id + ": the map already has a flight of that id");
  }
  for (int suffix = 2; taken(id); ++suffix) id = CleanedFlightId(wanted + "-" + std::to_string(suffix));
  if (id != wanted) {
    spdlog::warn(
        "{}: the map already has a flight '{}' from another log; this one is flight '{}' (name it with "
        "--flight-id or flight_id in meta.yaml)",
        spec, wanted, id);
  }
  identity->flight = id;
  source->SetFlightId(id);
  return Status::Ok();
}

// One source through the per-frame pass; its nodes and loop closures go to `outcome->places`.
Status MapSource(const MappingRequest& request, const std::string& spec, const Config& config,
                 const graph::TopoMap& prior, place::PlaceRecognizer* recognizer, ChangeMonitor* monitor,
                 MappingOutcome* outcome) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(OpenSource(spec, config.input, &source));
  PatrolRecord identity;
  PATROLMAP_RETURN_IF_ERROR(
      IdentifyFlight(spec, request.flight_id, KnownFlights(prior, *outcome), source.get(), &identity));
  if (!request.poses.empty()) PATROLMAP_RETURN_IF_ERROR(source->UsePoseFile(request.poses));
  if (!request.camera.empty()) PATROLMAP_RETURN_IF_ERROR(source->UseCameraFile(request.camera));
  const io::LogInfo& info = source->info();
  if (request.pass.node_every > 0 && !info.timed) {
    spdlog::warn(
        "{}: no timestamps: every image is a node, and images at most place.exclude_recent_images = {} before a "
        "query are not its candidates",
        spec, config.place.exclude_recent_images);
  }
  DriveOptions drive = request.drive;
  drive.paced = drive.paced && info.kind != "camera";
  FlightRun& run = outcome->flights.emplace_back();
  PATROLMAP_RETURN_IF_ERROR(
      RunFlight(source.get(), config, request.pass, drive, recognizer, &outcome->places, monitor, &run));
  run.result.record.source = identity.source;
  run.result.record.source_digest = identity.source_digest;
  if (run.drive.interrupted) spdlog::info("{}: stop requested: writing the map", spec);
  for (const std::string& warning : run.warnings) spdlog::warn("{}", warning);
  LogRecord(run.result);
  return WriteFlightOutputs(request, info, run.result, outcome->places);
}

// The latest patrol of `map` that has an evidence grid; none without.
const PatrolRecord* LatestGrid(const graph::TopoMap& map) {
  const std::vector<std::string> flights = map.Flights();
  for (auto flight = flights.rbegin(); flight != flights.rend(); ++flight) {
    const PatrolRecord* record = map.Patrol(*flight);
    if (record != nullptr && record->grid.voxel_size > 0.0 && !record->grid.voxels.empty()) return record;
  }
  return nullptr;
}

// Moves a new patrol onto the map's latest one with a grid, when a whole-voxel shift overlaps their surfaces
// clearly better (change/grid_alignment.h): the poses of two flights can share an offset.
void AlignToMap(const graph::TopoMap& map, const change::ChangeOptions& options, PatrolRecord* record) {
  const PatrolRecord* latest = LatestGrid(map);
  if (latest == nullptr) return;
  // Its grid as the site's latest state: a patrol read it with only the voxels no later patrol observed.
  std::vector<change::GridSource> sources;
  const PatrolRecord reference = change::LatestState(map, *latest, &sources);
  const change::GridShift shift = change::ChangeDetector(reference, options).Align(record);
  if (shift.applied) {
    spdlog::info("{}: {}", record->flight, change::DescribeShift(shift, record->grid.voxel_size, reference.flight));
  }
}

// The map of the run: the prior's nodes, the new ones, and the patrol record of each new flight, each aligned to
// the map's patrol before it. A flight too short for a key location keeps its record: its route frames, grid and
// objects can still be compared.
graph::TopoMap AssembleMap(const graph::TopoMap& prior, const graph::TopoMap::VocabularyTag& tag,
                           const change::ChangeOptions& options, MappingOutcome* outcome) {
  graph::TopoMap map = BuildTopoMap(outcome->places, &prior);
  map.set_vocabulary(tag);
  for (FlightRun& run : outcome->flights) {
    PatrolRecord& record = run.result.record;
    AlignToMap(map, options, &record);
    map.SetPatrol(std::move(record));
  }
  return map;
}

}  // namespace

Status RunMapping(const MappingRequest& request, MappingOutcome* outcome) {
  Config config;
  PATROLMAP_RETURN_IF_ERROR(CheckRequest(request, &config));
  graph::TopoMap prior;
  // What a new patrol is compared and aligned with is read whole; the rest of the earlier patrols stays in the file.
  if (!request.prior_map.empty()) {
    PATROLMAP_RETURN_IF_ERROR(graph::LoadMap(request.prior_map, &prior, graph::PatrolDetail::kLatest));
  }
  vocab::Vocabulary vocabulary;
  std::string vocabulary_path;
  PATROLMAP_RETURN_IF_ERROR(LoadSiftVocabulary(request.vocabulary_path, &vocabulary, &vocabulary_path));
  PATROLMAP_RETURN_IF_ERROR(CheckVocabulary(prior, request.prior_map, vocabulary, vocabulary_path));
  place::PlaceRecognizer recognizer(&vocabulary, config.place);
  PATROLMAP_RETURN_IF_ERROR(SeedRecognizer(prior, request.prior_map, vocabulary, &recognizer));
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(request.out));
  std::unique_ptr<ChangeMonitor> monitor;
  const std::vector<std::string> prior_flights = prior.Flights();
  if (request.events && !prior_flights.empty()) {
    PATROLMAP_RETURN_IF_ERROR(ChangeMonitor::Open(&prior, prior_flights.back(), config, *request.events,
                                                  request.out + "/events.jsonl", &monitor));
  }
  outcome->flights.reserve(request.sources.size());
  for (const std::string& source : request.sources) {
    PATROLMAP_RETURN_IF_ERROR(MapSource(request, source, config, prior, &recognizer, monitor.get(), outcome));
  }
  graph::TopoMap map = AssembleMap(prior, TagOf(vocabulary, vocabulary_path), ChangeOptionsOf(config), outcome);
  std::vector<change::ChangeItem> entries;
  if (!request.prior_map.empty()) {
    PATROLMAP_RETURN_IF_ERROR(ReportLastFlight(prior, &map, ChangeOptionsOf(config), request.out, &outcome->report,
                                               &outcome->compared, &entries));
  }
  change::NumberAllSiteObjects(&map);
  if (monitor != nullptr && outcome->compared) {
    PATROLMAP_RETURN_IF_ERROR(monitor->Close(outcome->report, map, entries));
  }
  if (monitor != nullptr) outcome->events = monitor->events();
  return SaveMapRun(&map, request.out, request.prior_map, config.map);
}

}  // namespace patrolmap::pipeline
