// eval::ScoreRun: a run's files against the simulated logs' ground truth.
#include "patrolmap/eval/run_score.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Dense>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

#include "patrolmap/change/report.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/change.h"

namespace patrolmap::eval {
namespace {

// A simulated log: its flight id, frame count and ground-truth places.
struct TruthLog {
  std::string path;
  io::LogInfo info;
  std::vector<Place> places;
};

Status LoadTruthLog(const std::string& path, bool need_places, TruthLog* log) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(path, {}, &source));
  log->path = path;
  log->info = source->info();
  return need_places ? ReadPlaces(path, &log->places) : Status::Ok();
}

// Key locations of RUN against the first log (Table II).
Status EvaluateKeyLocations(const std::string& run, const RunScoreOptions& options, const TruthLog& log,
                            nlohmann::json* report) {
  std::vector<KeyLocation> detected;
  std::vector<TruthEdge> edges;
  PATROLMAP_RETURN_IF_ERROR(ReadKeyLocationsCsv(run + "/key_locations.csv", &detected));
  PATROLMAP_RETURN_IF_ERROR(ReadTruthEdges(log.path, &edges));
  const KeyLocationScore score = ScoreKeyLocations(detected, edges, options.key_locations);
  (*report)["key_locations"] = {{"flight", log.info.flight_id},
                                {"frames", log.info.frame_count},
                                {"tolerance_s", options.key_locations.tolerance_s},
                                {"min_span_s", options.key_locations.min_span_s},
                                {"nodes", score.detected},
                                {"expected", score.expected},
                                {"true_positives", score.true_positives},
                                {"false_positives", score.false_positives},
                                {"missed", score.missed},
                                {"precision", score.precision()},
                                {"recall", score.recall()}};
  nlohmann::json spans = nlohmann::json::array();
  for (std::size_t i = 0; i < score.spans.size(); ++i) {
    const ExpectedSpan& span = score.spans[i];
    const int match = score.span_match[i];
    spans.push_back({{"start_s", std::isfinite(span.start_s) ? nlohmann::json(span.start_s) : nlohmann::json()},
                     {"end_s", std::isfinite(span.end_s) ? nlohmann::json(span.end_s) : nlohmann::json()},
                     {"kind", ToString(span.kind)},
                     {"required", span.required},
                     {"node", match >= 0 ? nlohmann::json(detected[match].node_index) : nlohmann::json()}});
  }
  (*report)["key_locations"]["spans"] = spans;
  return Status::Ok();
}

// Loop closures of RUN against the places of every log (Table III).
Status EvaluateLoopClosures(const std::string& run, const RunScoreOptions& options, const std::vector<TruthLog>& logs,
                            nlohmann::json* report) {
  std::vector<NodeRecord> nodes;
  std::vector<LoopClosureRecord> closures;
  PATROLMAP_RETURN_IF_ERROR(ReadNodesCsv(run + "/nodes.csv", &nodes));
  PATROLMAP_RETURN_IF_ERROR(ReadLoopClosuresCsv(run + "/loop_closures.csv", &closures));
  std::map<std::string, const TruthLog*> by_flight;
  for (const TruthLog& log : logs) by_flight[log.info.flight_id] = &log;
  std::vector<Place> places;
  for (const NodeRecord& node : nodes) {
    const auto log = by_flight.find(node.flight);
    if (log == by_flight.end())
      return Status::InvalidArgument(run + "/nodes.csv: node " + std::to_string(node.node) + " comes from flight '" +
                                     node.flight + "', which no --log holds");
    if (node.frame_index < 0 || node.frame_index >= static_cast<std::int64_t>(log->second->places.size())) {
      return Status::DataLoss(run + "/nodes.csv: node " + std::to_string(node.node) + ": frame " +
                              std::to_string(node.frame_index) + " is not in " + log->second->path);
    }
    places.push_back(log->second->places[node.frame_index]);
  }
  const LoopClosureScore score = ScoreLoopClosures(nodes, places, closures, options.loop_closures);
  (*report)["loop_closures"] = {{"radius_m", options.loop_closures.radius_m},
                                {"max_heading_deg", options.loop_closures.max_heading_deg},
                                {"min_gap_s", options.loop_closures.min_gap_s},
                                {"nodes", score.nodes},
                                {"possible", score.possible},
                                {"found", score.found},
                                {"reported", score.reported},
                                {"false_positives", score.false_positives},
                                {"precision", score.precision()},
                                {"recall", score.recall()}};
  return Status::Ok();
}

nlohmann::json CountsJson(const Counts& c) {
  return {{"true_positives", c.true_positives},
          {"false_positives", c.false_positives},
          {"false_negatives", c.false_negatives},
          {"precision", c.Precision()},
          {"recall", c.Recall()},
          {"f1", c.F1()}};
}

// Whether each end of `change` that a flight of `map` could see lay whole in the image in options.min_whole_views
// of that flight's views at the truth detector's sightings.
bool Observable(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                const TrueChange& change, const ChangeScoreOptions& options) {
  for (const bool was : {true, false}) {
    const TruthObject* object = was ? change.before : change.after;
    const PatrolRecord* record = map.Patrol(was ? prior : current);
    if (object == nullptr) continue;
    if (record == nullptr || !record->camera.valid()) return false;
    std::vector<CameraPoseSample> views;
    for (const TimestampNs time_ns : object->seen_ns) {
      if (const std::optional<CameraPoseSample> pose = io::PoseAt(record->views, time_ns)) views.push_back(*pose);
    }
    if (SightingsOf(*object, views, record->camera, record->distortion).whole < options.min_whole_views) {
      return false;
    }
  }
  return true;
}

// The fused list per entry, over all true changes and over the observable ones.
nlohmann::json EntriesJson(const EntryScore& score) {
  return {{"entries", score.entries},
          {"bearings", score.bearings},
          {"true_entries", score.true_entries},
          {"false_ids", score.false_ids},
          {"true_changes", score.all.true_positives + score.all.false_negatives},
          {"found", score.all.true_positives},
          {"observable", score.observable.true_positives + score.observable.false_negatives},
          {"observable_found", score.observable.true_positives},
          {"missed_ids", score.missed_ids},
          {"precision", score.Precision()},
          {"recall", score.Recall(false)},
          {"recall_observable", score.Recall(true)},
          {"f1", score.F1(false)},
          {"f1_observable", score.F1(true)}};
}

std::vector<ReportedEntry> ReportedEntries(const change::ChangesFile& file) {
  std::vector<ReportedEntry> entries;
  for (const change::ChangesFile::Entry& e : file.entries) entries.push_back({e.id, e.position, e.from});
  return entries;
}

std::vector<ReportedObject> ReportedObjects(const change::ChangesFile& file) {
  std::vector<ReportedObject> objects;
  for (const change::ChangesFile::Object& o : file.objects) {
    objects.push_back({o.state, o.label, o.before, o.after, o.from_geometry, o.id});
  }
  return objects;
}

// Each required true change (found or missed) and each false report, with the id of the report concerned.
nlohmann::json OutcomesJson(const std::vector<ObjectOutcome>& outcomes, const std::vector<ReportedObject>& reported) {
  const auto point = [](const std::optional<Eigen::Vector2d>& p) {
    return p ? nlohmann::json::array({p->x(), p->y()}) : nlohmann::json();
  };
  nlohmann::json list = nlohmann::json::array();
  for (const ObjectOutcome& o : outcomes) {
    nlohmann::json id;  // null for a missed change
    if (o.reported >= 0) id = reported[static_cast<std::size_t>(o.reported)].id;
    list.push_back({{"state", o.state},
                    {"outcome", o.outcome},
                    {"label", o.label},
                    {"before", point(o.before)},
                    {"after", point(o.after)},
                    {"report_id", id}});
  }
  return list;
}

// Adds to each true change in `list` (OutcomesJson of `outcomes`) how the two flights of `map` saw it
// (SightingsOf, from the poses the map keeps at the truth detector's sightings): `seen_before` the prior flight
// where the object was, `seen_after` the current one where it is.
void AddSightings(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                  const std::vector<ObjectOutcome>& outcomes, const std::vector<TruthObject>& before,
                  const std::vector<TruthObject>& after, nlohmann::json* list) {
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    const ObjectOutcome& o = outcomes[i];
    if (o.id < 0) continue;
    for (const bool was : {true, false}) {
      const PatrolRecord* record = map.Patrol(was ? prior : current);
      const TruthObject* object = FindId(was ? before : after, o.id);
      if (!(was ? o.before : o.after) || record == nullptr || !record->camera.valid() || object == nullptr) continue;
      std::vector<CameraPoseSample> views;
      for (const TimestampNs time_ns : object->seen_ns) {
        if (const std::optional<CameraPoseSample> pose = io::PoseAt(record->views, time_ns)) views.push_back(*pose);
      }
      const Sightings seen = SightingsOf(*object, views, record->camera, record->distortion);
      (*list)[i][was ? "seen_before" : "seen_after"] = {
          {"views", seen.views}, {"whole", seen.whole}, {"nearest_m", seen.nearest_m}, {"farthest_m", seen.farthest_m}};
    }
  }
}

// Geometry of the recomputed report, per voxel.
void ScoreGeometryOf(const graph::TopoMap& map, const change::ChangeReport& report,
                     const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                     const ChangeScoreOptions& options, nlohmann::json* result) {
  const GeometryScore score = ScoreGeometry(report.geometry.changed_voxels, map.Patrol(report.prior_flight)->grid,
                                            map.Patrol(report.current_flight)->grid, before, after, options);
  (*result)["geometry"] = CountsJson(score.voxels);
  (*result)["geometry"]["iou"] = score.Iou();
  (*result)["geometry"]["observed_voxels"] = score.observed_voxels;
  (*result)["geometry"]["false_positives_near_change"] = score.false_near_change;
  (*result)["geometry"]["near_change_m"] = options.near_change_m;
  (*result)["geometry"]["regions"] = report.geometry.regions.size();
  (*result)["geometry"]["surface_voxels"] = report.geometry.surface_voxels;
  (*result)["geometry"]["differing_voxels"] = report.geometry.differing_voxels;
}

// The visible object changes in the key frame of `node` (a node of the flight whose objects are `here`), from
// the flight's patrol record; false without one.
bool KeyFrameTruth(const graph::TopoMap& map, int node, const std::vector<TruthObject>& here,
                   const std::vector<TruthObject>& other, const ChangeScoreOptions& options,
                   std::vector<cv::Rect2d>* boxes) {
  const KeyFrameNode& n = map.node(node);
  const PatrolRecord* patrol = map.Patrol(n.flight);
  if (patrol == nullptr || !patrol->camera.valid() || n.thumbnail.empty()) return false;
  const std::optional<CameraPoseSample> pose = io::PoseAt(patrol->views, n.timestamp_ns);
  if (!pose) return false;
  const CameraIntrinsics thumbnail =
      patrol->camera.Scaled(static_cast<double>(n.thumbnail.cols) / patrol->camera.width);
  *boxes = VisibleChangeBoxes(here, other, n.timestamp_ns, *pose, thumbnail, options, patrol->distortion);
  return true;
}

// Appearance regions of the recomputed report against the object changes visible in the two key frames.
void ScoreAppearanceOf(const graph::TopoMap& map, const change::ChangeReport& report,
                       const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                       const change::AppearanceOptions& appearance, ChangeScoreOptions options,
                       nlohmann::json* result) {
  std::vector<PlaceTruth> truth;
  std::vector<std::vector<RegionBoxes>> regions;
  for (const change::PlaceChange& place : report.places) {
    if (!place.appearance.registered) continue;
    const cv::Mat& thumbnail = map.node(place.current_node).thumbnail;
    options.min_area_px = appearance.min_area_fraction * thumbnail.total();
    PlaceTruth t;
    if (!KeyFrameTruth(map, place.prior_node, before, after, options, &t.prior) ||
        !KeyFrameTruth(map, place.current_node, after, before, options, &t.current)) {
      continue;
    }
    Eigen::Matrix3d current_from_prior;
    cv::cv2eigen(place.appearance.homography, current_from_prior);
    const cv::Mat& prior_thumbnail = map.node(place.prior_node).thumbnail;
    KeepInOverlap(current_from_prior, thumbnail.cols, thumbnail.rows, &t.prior);
    KeepInOverlap(current_from_prior.inverse(), prior_thumbnail.cols, prior_thumbnail.rows, &t.current);
    truth.push_back(t);
    regions.emplace_back();
    for (const change::AppearanceRegion& r : place.appearance.regions)
      regions.back().push_back({r.prior_box, r.current_box});
  }
  if (truth.empty()) return;
  const AppearanceScore score = ScoreAppearance(truth, regions, options);
  (*result)["appearance"] = {{"places", truth.size()},
                             {"regions", score.regions},
                             {"regions_on_change", score.regions_on_change},
                             {"changes", score.changes},
                             {"changes_found", score.changes_found},
                             {"precision", score.Precision()},
                             {"recall", score.Recall()}};
}

constexpr double kVisibleShare = 0.002;  // a change is visible in a route frame when its box covers 0.2 % of it

// The object changes visible in a route frame of `record` (whose flight's objects are `here`); false without a
// pose or picture.
bool RouteFrameTruth(const PatrolRecord& record, const RouteFrame& frame, const std::vector<TruthObject>& here,
                     const std::vector<TruthObject>& other, ChangeScoreOptions options,
                     std::vector<VisibleChange>* changes, cv::Size* size) {
  const cv::Mat image = cv::imdecode(frame.jpeg, cv::IMREAD_GRAYSCALE);
  const std::optional<CameraPoseSample> pose = frame.pose ? frame.pose : io::PoseAt(record.views, frame.timestamp_ns);
  if (image.empty() || !pose || !record.camera.valid()) return false;
  options.min_area_px = kVisibleShare * image.total();
  const CameraIntrinsics camera = record.camera.Scaled(static_cast<double>(image.cols) / record.camera.width);
  *changes = VisibleChanges(here, other, frame.timestamp_ns, *pose, camera, options, record.distortion);
  *size = image.size();
  return true;
}

// Keeps the changes whose centre `to_other` maps inside an image of `size`.
void KeepInside(const Eigen::Matrix3d& to_other, const cv::Size& size, std::vector<VisibleChange>* changes) {
  changes->erase(std::remove_if(changes->begin(), changes->end(),
                                [&](const VisibleChange& c) {
                                  return !CentreMapsInside(to_other, size.width, size.height, c.box);
                                }),
                 changes->end());
}

// The regions of the scored pairs that no change reports, with the step that dropped them: the appearance
// tests in their order, then the second prior frame, then the vote.
std::vector<RouteCandidate> RouteCandidates(const change::RouteComparison& route, const std::vector<bool>& scored) {
  std::vector<std::vector<bool>> voted(route.pairs.size());
  for (std::size_t i = 0; i < route.pairs.size(); ++i) voted[i].assign(route.pairs[i].appearance.regions.size(), false);
  for (const change::RouteChange& change : route.changes) {
    for (const change::RouteChange::View& v : change.views) voted[v.pair][v.region] = true;
  }
  std::vector<RouteCandidate> candidates;
  const auto add = [&](int pair, const change::AppearanceRegion& region, int step, const std::string& name) {
    candidates.push_back({pair, {region.prior_box, region.current_box}, step, name});
  };
  constexpr int kNotVotedStep = static_cast<int>(change::DropReason::kNotSeenFromSecondPrior) + 1;
  for (std::size_t i = 0; i < route.pairs.size(); ++i) {
    if (!scored[i]) continue;
    const change::AppearanceChange& appearance = route.pairs[i].appearance;
    for (const change::DroppedRegion& d : appearance.dropped)
      add(static_cast<int>(i), d.region, static_cast<int>(d.reason), change::DropReasonName(d.reason));
    for (std::size_t r = 0; r < appearance.regions.size(); ++r) {
      if (!voted[i][r]) add(static_cast<int>(i), appearance.regions[r], kNotVotedStep, "not_voted");
    }
  }
  return candidates;
}

// Appearance along the route of the recomputed report against the object changes visible in its compared pairs.
void ScoreRouteOf(const graph::TopoMap& map, const change::ChangeReport& report, const std::vector<TruthObject>& before,
                  const std::vector<TruthObject>& after, const ChangeScoreOptions& options, nlohmann::json* result) {
  const PatrolRecord* prior = map.Patrol(report.prior_flight);
  const PatrolRecord* current = map.Patrol(report.current_flight);
  if (!report.route.compared || prior == nullptr || current == nullptr) return;
  std::vector<RoutePairTruth> truth(report.route.pairs.size());
  std::vector<bool> scored(report.route.pairs.size(), false);
  for (std::size_t i = 0; i < report.route.pairs.size(); ++i) {
    const change::RoutePair& pair = report.route.pairs[i];
    cv::Size prior_size, current_size;
    if (!RouteFrameTruth(*prior, prior->route[pair.prior], before, after, options, &truth[i].prior, &prior_size) ||
        !RouteFrameTruth(*current, current->route[pair.current], after, before, options, &truth[i].current,
                         &current_size)) {
      continue;
    }
    Eigen::Matrix3d current_from_prior;
    cv::cv2eigen(pair.appearance.homography, current_from_prior);
    KeepInside(current_from_prior, current_size, &truth[i].prior);
    KeepInside(current_from_prior.inverse(), prior_size, &truth[i].current);
    scored[i] = true;
  }
  std::vector<ReportedRouteChange> reported;
  for (const change::RouteChange& change : report.route.changes) {
    ReportedRouteChange r;
    for (const change::RouteChange::View& v : change.views) {
      if (!scored[v.pair]) continue;
      const change::AppearanceRegion& region = report.route.pairs[v.pair].appearance.regions[v.region];
      r.pairs.push_back(v.pair);
      r.boxes.push_back({region.prior_box, region.current_box});
    }
    r.confidence = change.confidence;
    reported.push_back(r);
  }
  const RouteScore score = ScoreRoute(truth, reported, RouteCandidates(report.route, scored), options);
  (*result)["route"] = {{"frames", report.route.current_frames},
                        {"pairs", report.route.pairs.size()},
                        {"compared_share", report.route.ComparedShare()},
                        {"changes", score.changes},
                        {"changes_on_change", score.changes_on_truth},
                        {"visible", score.visible},
                        {"found", score.found},
                        {"visible_in_prior", score.visible_in_prior},
                        {"found_in_prior", score.found_in_prior},
                        {"precision", score.Precision()},
                        {"recall", score.Recall()},
                        {"lost_at", score.lost_at},
                        {"average_precision", AveragePrecision(score.ranked)},
                        {"ranked", score.ranked}};
}

// The object channel per state (with how the flights saw each true change when the run's map is there), and over
// the true changes as a whole, all and observable ones.
void ScoreObjectsOf(const change::ChangesFile& file, const std::vector<TrueChange>& truth,
                    const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                    const ChangeScoreOptions& options, const graph::TopoMap* map, nlohmann::json* result) {
  const std::vector<ReportedObject> reported = ReportedObjects(file);
  const ObjectChangeScore score = ScoreObjectChanges(reported, before, after, options);
  nlohmann::json& objects = (*result)["objects"];
  for (const auto& [state, counts] : score.by_state) objects[state] = CountsJson(counts);
  objects["unobserved_reported"] = score.unobserved;
  objects["outcomes"] = OutcomesJson(score.outcomes, reported);
  if (map != nullptr) {
    AddSightings(*map, file.prior_flight, file.current_flight, score.outcomes, before, after, &objects["outcomes"]);
  }
  const ObjectChangeTotals totals = TotalObjectChanges(score, truth);
  objects["changes"] = CountsJson(totals.all);
  if (map != nullptr) objects["observable_changes"] = CountsJson(totals.observable);
}

// Geometry and appearance of the comparison recomputed from the run's map with the run's change options.
Status ScoreRecomputed(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                       const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                       const RunScoreOptions& options, nlohmann::json* result) {
  change::ChangeReport recomputed;
  PATROLMAP_RETURN_IF_ERROR(pipeline::CompareFlights(map, prior, current, options.change, &recomputed));
  ChangeScoreOptions scoring = options.changes;
  scoring.min_observations = options.change.geometry.min_observations;
  if (recomputed.geometry_compared) ScoreGeometryOf(map, recomputed, before, after, scoring, result);
  ScoreAppearanceOf(map, recomputed, before, after, options.change.appearance, scoring, result);
  ScoreRouteOf(map, recomputed, before, after, scoring, result);
  return Status::Ok();
}

// Site ids over the patrols of `map` whose flights `logs` hold, in the order flown (ScoreSiteIds).
Status ScoreSiteObjectsOf(const graph::TopoMap& map, const std::vector<TruthLog>& logs,
                          const ChangeScoreOptions& options, nlohmann::json* result) {
  std::vector<std::vector<std::pair<int, int>>> patrols;
  for (const std::string& flight : map.Flights()) {
    const PatrolRecord* record = map.Patrol(flight);
    const auto log =
        std::find_if(logs.begin(), logs.end(), [&](const TruthLog& l) { return l.info.flight_id == flight; });
    if (record == nullptr || !record->has_objects || log == logs.end()) continue;
    std::vector<TruthObject> truth;
    PATROLMAP_RETURN_IF_ERROR(ReadTruthObjects(log->path, &truth));
    patrols.emplace_back();
    for (const MapObject& o : record->objects) {
      if (o.confirmed) patrols.back().emplace_back(o.site_id, TruthIdOf(o, truth, options));
    }
  }
  if (patrols.size() < 2) return Status::Ok();
  const SiteIdScore score = ScoreSiteIds(patrols);
  (*result)["site_objects"] = {{"patrols", patrols.size()}, {"tracked", score.tracked},
                               {"kept", score.kept},        {"changed", score.changed},
                               {"merged", score.merged},    {"persistence", score.Persistence()}};
  return Status::Ok();
}

// Changes of RUN (changes.json, and the map.pmap beside it) against the two flights' ground truth.
Status EvaluateChanges(const std::string& run, const RunScoreOptions& options, const std::vector<TruthLog>& logs,
                       nlohmann::json* report) {
  const std::string path = run + "/changes.json";
  change::ChangesFile file;
  PATROLMAP_RETURN_IF_ERROR(change::ReadChangesJson(path, &file));
  const std::string& prior = file.prior_flight;
  const std::string& current = file.current_flight;
  const TruthLog *prior_log = nullptr, *current_log = nullptr;
  for (const TruthLog& log : logs) {
    if (log.info.flight_id == prior) prior_log = &log;
    if (log.info.flight_id == current) current_log = &log;
  }
  if (prior_log == nullptr || current_log == nullptr) {
    return Status::InvalidArgument(path + ": compares '" + prior + "' with '" + current +
                                   "': pass both logs with --log");
  }
  std::vector<TruthObject> before, after;
  PATROLMAP_RETURN_IF_ERROR(ReadTruthObjects(prior_log->path, &before));
  PATROLMAP_RETURN_IF_ERROR(ReadTruthObjects(current_log->path, &after));
  nlohmann::json result = {{"prior_flight", prior},
                           {"current_flight", current},
                           {"distance_m", options.changes.distance_m},
                           {"places_compared", file.places_compared},
                           {"places_changed", file.places_changed}};
  graph::TopoMap map;
  const bool has_map = std::filesystem::exists(run + "/map.pmap");
  if (has_map) PATROLMAP_RETURN_IF_ERROR(graph::LoadMap(run + "/map.pmap", &map));
  std::vector<TrueChange> truth = TrueChanges(before, after);
  for (TrueChange& change : truth)
    change.observable = has_map && Observable(map, prior, current, change, options.changes);
  if (file.objects_compared) {
    ScoreObjectsOf(file, truth, before, after, options.changes, has_map ? &map : nullptr, &result);
  }
  if (has_map) {
    result["entries"] = EntriesJson(ScoreEntries(ReportedEntries(file), truth, options.changes));
    PATROLMAP_RETURN_IF_ERROR(ScoreSiteObjectsOf(map, logs, options.changes, &result));
    PATROLMAP_RETURN_IF_ERROR(ScoreRecomputed(map, prior, current, before, after, options, &result));
  }
  (*report)["changes"] = result;
  return Status::Ok();
}

}  // namespace

Status ScoreRun(const std::string& run, const std::vector<std::string>& log_paths, const RunScoreOptions& options,
                nlohmann::json* report) {
  const bool has_key_locations = std::filesystem::exists(run + "/key_locations.csv");
  const bool has_loop_closures = std::filesystem::exists(run + "/loop_closures.csv");
  const bool has_changes = std::filesystem::exists(run + "/changes.json");
  if (!has_key_locations && !has_loop_closures && !has_changes) {
    return Status::NotFound(run + ": holds none of key_locations.csv, loop_closures.csv, changes.json");
  }
  if (log_paths.empty()) return Status::InvalidArgument(run + ": no simulated log to score it against");
  std::vector<TruthLog> logs(log_paths.size());
  for (std::size_t i = 0; i < logs.size(); ++i) {
    PATROLMAP_RETURN_IF_ERROR(LoadTruthLog(log_paths[i], has_loop_closures, &logs[i]));
  }
  *report = {{"schema", "patrolmap.eval/1"}, {"run", run}};
  if (has_key_locations) PATROLMAP_RETURN_IF_ERROR(EvaluateKeyLocations(run, options, logs.front(), report));
  if (has_loop_closures) PATROLMAP_RETURN_IF_ERROR(EvaluateLoopClosures(run, options, logs, report));
  if (has_changes) PATROLMAP_RETURN_IF_ERROR(EvaluateChanges(run, options, logs, report));
  return Status::Ok();
}

}  // namespace patrolmap::eval
