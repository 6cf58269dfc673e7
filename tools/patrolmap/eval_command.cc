// patrolmap eval RUN --log LOG [--log LOG ...] [--json] [--tolerance S] [--min-span S] [--radius M] ...
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>
#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

#include "commands.h"
#include "common.h"
#include "patrolmap/eval/change_score.h"
#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/eval/loop_closure_score.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/pipeline/change.h"

namespace patrolmap::tools {
namespace {

struct EvalArguments {
  std::string run;
  std::vector<std::string> logs;
  bool json = false;
  bool verbose = false;
  eval::KeyLocationScoreOptions key_locations;
  eval::LoopClosureScoreOptions loop_closures;
  eval::ChangeScoreOptions changes;
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
};

// A simulated log: its flight id, frame count and ground-truth places.
struct TruthLog {
  std::string path;
  io::LogInfo info;
  std::vector<eval::Place> places;
};

Status LoadTruthLog(const std::string& path, bool need_places, TruthLog* log) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(path, {}, &source));
  log->path = path;
  log->info = source->info();
  return need_places ? eval::ReadPlaces(path, &log->places) : Status::Ok();
}

// Key locations of RUN against the first log (Table II).
Status EvaluateKeyLocations(const EvalArguments& arguments, const TruthLog& log, nlohmann::json* report) {
  std::vector<KeyLocation> detected;
  std::vector<eval::TruthEdge> edges;
  PATROLMAP_RETURN_IF_ERROR(eval::ReadKeyLocationsCsv(arguments.run + "/key_locations.csv", &detected));
  PATROLMAP_RETURN_IF_ERROR(eval::ReadTruthEdges(log.path, &edges));
  const eval::KeyLocationScore score = eval::ScoreKeyLocations(detected, edges, arguments.key_locations);
  (*report)["key_locations"] = {{"flight", log.info.flight_id},
                                {"frames", log.info.frame_count},
                                {"tolerance_s", arguments.key_locations.tolerance_s},
                                {"min_span_s", arguments.key_locations.min_span_s},
                                {"nodes", score.detected},
                                {"expected", score.expected},
                                {"true_positives", score.true_positives},
                                {"false_positives", score.false_positives},
                                {"missed", score.missed},
                                {"precision", score.precision()},
                                {"recall", score.recall()}};
  if (arguments.verbose && !arguments.json) {
    for (std::size_t i = 0; i < score.spans.size(); ++i) {
      const eval::ExpectedSpan& span = score.spans[i];
      const int match = score.span_match[i];
      std::printf("  span %7.2f .. %7.2f s  %-6s %-8s -> %s\n", span.start_s, span.end_s, ToString(span.kind),
                  span.required ? "required" : "optional",
                  match >= 0 ? ("node " + std::to_string(detected[match].node_index)).c_str() : "-");
    }
  }
  return Status::Ok();
}

// Loop closures of RUN against the places of every log (Table III).
Status EvaluateLoopClosures(const EvalArguments& arguments, const std::vector<TruthLog>& logs, nlohmann::json* report) {
  std::vector<eval::NodeRecord> nodes;
  std::vector<eval::LoopClosureRecord> closures;
  PATROLMAP_RETURN_IF_ERROR(eval::ReadNodesCsv(arguments.run + "/nodes.csv", &nodes));
  PATROLMAP_RETURN_IF_ERROR(eval::ReadLoopClosuresCsv(arguments.run + "/loop_closures.csv", &closures));
  std::map<std::string, const TruthLog*> by_flight;
  for (const TruthLog& log : logs) by_flight[log.info.flight_id] = &log;
  std::vector<eval::Place> places;
  for (const eval::NodeRecord& node : nodes) {
    const auto log = by_flight.find(node.flight);
    if (log == by_flight.end())
      return Status::InvalidArgument(arguments.run + "/nodes.csv: node " + std::to_string(node.node) +
                                     " comes from flight '" + node.flight + "', which no --log holds");
    if (node.frame_index < 0 || node.frame_index >= static_cast<std::int64_t>(log->second->places.size())) {
      return Status::DataLoss(arguments.run + "/nodes.csv: node " + std::to_string(node.node) + ": frame " +
                              std::to_string(node.frame_index) + " is not in " + log->second->path);
    }
    places.push_back(log->second->places[node.frame_index]);
  }
  const eval::LoopClosureScore score = eval::ScoreLoopClosures(nodes, places, closures, arguments.loop_closures);
  (*report)["loop_closures"] = {{"radius_m", arguments.loop_closures.radius_m},
                                {"max_heading_deg", arguments.loop_closures.max_heading_deg},
                                {"min_gap_s", arguments.loop_closures.min_gap_s},
                                {"nodes", score.nodes},
                                {"possible", score.possible},
                                {"found", score.found},
                                {"reported", score.reported},
                                {"false_positives", score.false_positives},
                                {"precision", score.precision()},
                                {"recall", score.recall()}};
  return Status::Ok();
}

nlohmann::json CountsJson(const eval::Counts& c) {
  return {{"true_positives", c.true_positives},
          {"false_positives", c.false_positives},
          {"false_negatives", c.false_negatives},
          {"precision", c.Precision()},
          {"recall", c.Recall()},
          {"f1", c.F1()}};
}

Status ReadReportedObjects(const std::string& path, const nlohmann::json& objects,
                           std::vector<eval::ReportedObject>* reported) {
  try {
    for (const nlohmann::json& o : objects) {
      eval::ReportedObject r;
      r.state = o.at("state").get<std::string>();
      r.label = o.at("label").get<std::string>();
      r.class_agnostic = o.value("source", "detections") == "geometry";
      r.id = o.value("id", "");
      for (const char* key : {"before", "after"}) {
        if (o.at(key).is_null()) continue;
        const Eigen::Vector3d p(o[key][0].get<double>(), o[key][1].get<double>(), o[key][2].get<double>());
        (std::string(key) == "before" ? r.before : r.after) = p;
      }
      reported->push_back(r);
    }
  } catch (const nlohmann::json::exception& e) {
    return Status::DataLoss(path + ": malformed objects: " + e.what());
  }
  return Status::Ok();
}

// The fused change list's entries (changes.json "changes").
Status ReadReportedEntries(const std::string& path, const nlohmann::json& changes,
                           std::vector<eval::ReportedEntry>* entries) {
  const auto point = [](const nlohmann::json& p) -> std::optional<Eigen::Vector3d> {
    if (p.is_null()) return std::nullopt;
    return Eigen::Vector3d(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
  };
  try {
    for (const nlohmann::json& c : changes) {
      entries->push_back({c.at("id").get<std::string>(), point(c.at("position")), point(c.at("from"))});
    }
  } catch (const nlohmann::json::exception& e) {
    return Status::DataLoss(path + ": malformed changes: " + e.what());
  }
  return Status::Ok();
}

// Whether each end of `change` that a flight of `map` could see lay whole in the image in options.min_whole_views
// of that flight's views at the truth detector's sightings.
bool Observable(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                const eval::TrueChange& change, const eval::ChangeScoreOptions& options) {
  for (const bool was : {true, false}) {
    const eval::TruthObject* object = was ? change.before : change.after;
    const PatrolRecord* record = map.Patrol(was ? prior : current);
    if (object == nullptr) continue;
    if (record == nullptr || !record->camera.valid()) return false;
    std::vector<CameraPoseSample> views;
    for (const TimestampNs time_ns : object->seen_ns) {
      if (const std::optional<CameraPoseSample> pose = io::PoseAt(record->views, time_ns)) views.push_back(*pose);
    }
    if (eval::SightingsOf(*object, views, record->camera, record->distortion).whole < options.min_whole_views) {
      return false;
    }
  }
  return true;
}

// The fused list per entry, over all true changes and over the observable ones.
void ScoreEntriesOf(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                    const std::vector<eval::ReportedEntry>& entries, const std::vector<eval::TruthObject>& before,
                    const std::vector<eval::TruthObject>& after, const eval::ChangeScoreOptions& options,
                    nlohmann::json* result) {
  std::vector<eval::TrueChange> truth = eval::TrueChanges(before, after);
  for (eval::TrueChange& change : truth) change.observable = Observable(map, prior, current, change, options);
  const eval::EntryScore score = eval::ScoreEntries(entries, truth, options);
  (*result)["entries"] = {{"entries", score.entries},
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

// Each required true change (found or missed) and each false report, with the id of the report concerned.
nlohmann::json OutcomesJson(const std::vector<eval::ObjectOutcome>& outcomes,
                            const std::vector<eval::ReportedObject>& reported) {
  const auto point = [](const std::optional<Eigen::Vector2d>& p) {
    return p ? nlohmann::json::array({p->x(), p->y()}) : nlohmann::json();
  };
  nlohmann::json list = nlohmann::json::array();
  for (const eval::ObjectOutcome& o : outcomes) {
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
// (eval::SightingsOf, from the poses the map keeps at the truth detector's sightings): `seen_before` the prior flight
// where the object was, `seen_after` the current one where it is.
void AddSightings(const graph::TopoMap& map, const std::string& prior, const std::string& current,
                  const std::vector<eval::ObjectOutcome>& outcomes, const std::vector<eval::TruthObject>& before,
                  const std::vector<eval::TruthObject>& after, nlohmann::json* list) {
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    const eval::ObjectOutcome& o = outcomes[i];
    if (o.id < 0) continue;
    for (const bool was : {true, false}) {
      const PatrolRecord* record = map.Patrol(was ? prior : current);
      const eval::TruthObject* object = eval::FindId(was ? before : after, o.id);
      if (!(was ? o.before : o.after) || record == nullptr || !record->camera.valid() || object == nullptr) continue;
      std::vector<CameraPoseSample> views;
      for (const TimestampNs time_ns : object->seen_ns) {
        if (const std::optional<CameraPoseSample> pose = io::PoseAt(record->views, time_ns)) views.push_back(*pose);
      }
      const eval::Sightings seen = eval::SightingsOf(*object, views, record->camera, record->distortion);
      (*list)[i][was ? "seen_before" : "seen_after"] = {
          {"views", seen.views}, {"whole", seen.whole}, {"nearest_m", seen.nearest_m}, {"farthest_m", seen.farthest_m}};
    }
  }
}

// Geometry of the recomputed report, per voxel.
void ScoreGeometryOf(const graph::TopoMap& map, const change::ChangeReport& report,
                     const std::vector<eval::TruthObject>& before, const std::vector<eval::TruthObject>& after,
                     const eval::ChangeScoreOptions& options, nlohmann::json* result) {
  const eval::GeometryScore score =
      eval::ScoreGeometry(report.geometry.changed_voxels, map.Patrol(report.prior_flight)->grid,
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
bool KeyFrameTruth(const graph::TopoMap& map, int node, const std::vector<eval::TruthObject>& here,
                   const std::vector<eval::TruthObject>& other, const eval::ChangeScoreOptions& options,
                   std::vector<cv::Rect2d>* boxes) {
  const graph::NodeData& n = map.node(node);
  const PatrolRecord* patrol = map.Patrol(n.flight);
  if (patrol == nullptr || !patrol->camera.valid() || n.thumbnail.empty()) return false;
  const std::optional<CameraPoseSample> pose = io::PoseAt(patrol->views, n.timestamp_ns);
  if (!pose) return false;
  const CameraIntrinsics thumbnail =
      patrol->camera.Scaled(static_cast<double>(n.thumbnail.cols) / patrol->camera.width);
  *boxes = eval::VisibleChangeBoxes(here, other, n.timestamp_ns, *pose, thumbnail, options, patrol->distortion);
  return true;
}

// Appearance regions of the recomputed report against the object changes visible in the two key frames.
void ScoreAppearanceOf(const graph::TopoMap& map, const change::ChangeReport& report,
                       const std::vector<eval::TruthObject>& before, const std::vector<eval::TruthObject>& after,
                       const change::AppearanceOptions& appearance, eval::ChangeScoreOptions options,
                       nlohmann::json* result) {
  std::vector<eval::PlaceTruth> truth;
  std::vector<std::vector<eval::RegionBoxes>> regions;
  for (const change::PlaceChange& place : report.places) {
    if (!place.appearance.registered) continue;
    const cv::Mat& thumbnail = map.node(place.current_node).thumbnail;
    options.min_area_px = appearance.min_area_fraction * thumbnail.total();
    eval::PlaceTruth t;
    if (!KeyFrameTruth(map, place.prior_node, before, after, options, &t.prior) ||
        !KeyFrameTruth(map, place.current_node, after, before, options, &t.current)) {
      continue;
    }
    Eigen::Matrix3d current_from_prior;
    cv::cv2eigen(place.appearance.homography, current_from_prior);
    const cv::Mat& prior_thumbnail = map.node(place.prior_node).thumbnail;
    eval::KeepInOverlap(current_from_prior, thumbnail.cols, thumbnail.rows, &t.prior);
    eval::KeepInOverlap(current_from_prior.inverse(), prior_thumbnail.cols, prior_thumbnail.rows, &t.current);
    truth.push_back(t);
    regions.emplace_back();
    for (const change::AppearanceRegion& r : place.appearance.regions)
      regions.back().push_back({r.prior_box, r.current_box});
  }
  if (truth.empty()) return;
  const eval::AppearanceScore score = eval::ScoreAppearance(truth, regions, options);
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
bool RouteFrameTruth(const PatrolRecord& record, const RouteFrame& frame, const std::vector<eval::TruthObject>& here,
                     const std::vector<eval::TruthObject>& other, eval::ChangeScoreOptions options,
                     std::vector<eval::VisibleChange>* changes, cv::Size* size) {
  const cv::Mat image = cv::imdecode(frame.jpeg, cv::IMREAD_GRAYSCALE);
  const std::optional<CameraPoseSample> pose = frame.pose ? frame.pose : io::PoseAt(record.views, frame.timestamp_ns);
  if (image.empty() || !pose || !record.camera.valid()) return false;
  options.min_area_px = kVisibleShare * image.total();
  const CameraIntrinsics camera = record.camera.Scaled(static_cast<double>(image.cols) / record.camera.width);
  *changes = eval::VisibleChanges(here, other, frame.timestamp_ns, *pose, camera, options, record.distortion);
  *size = image.size();
  return true;
}

// Keeps the changes whose centre `to_other` maps inside an image of `size`.
void KeepInside(const Eigen::Matrix3d& to_other, const cv::Size& size, std::vector<eval::VisibleChange>* changes) {
  changes->erase(std::remove_if(changes->begin(), changes->end(),
                                [&](const eval::VisibleChange& c) {
                                  return !eval::CentreMapsInside(to_other, size.width, size.height, c.box);
                                }),
                 changes->end());
}

// The regions of the scored pairs that no change reports, with the step that dropped them: the appearance
// tests in their order, then the second prior frame, then the vote.
std::vector<eval::RouteCandidate> RouteCandidates(const change::RouteComparison& route,
                                                  const std::vector<bool>& scored) {
  std::vector<std::vector<bool>> voted(route.pairs.size());
  for (std::size_t i = 0; i < route.pairs.size(); ++i) voted[i].assign(route.pairs[i].appearance.regions.size(), false);
  for (const change::RouteChange& change : route.changes) {
    for (const change::RouteChange::View& v : change.views) voted[v.pair][v.region] = true;
  }
  std::vector<eval::RouteCandidate> candidates;
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
void ScoreRouteOf(const graph::TopoMap& map, const change::ChangeReport& report,
                  const std::vector<eval::TruthObject>& before, const std::vector<eval::TruthObject>& after,
                  const eval::ChangeScoreOptions& options, nlohmann::json* result) {
  const PatrolRecord* prior = map.Patrol(report.prior_flight);
  const PatrolRecord* current = map.Patrol(report.current_flight);
  if (!report.route.compared || prior == nullptr || current == nullptr) return;
  std::vector<eval::RoutePairTruth> truth(report.route.pairs.size());
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
  std::vector<eval::ReportedRouteChange> reported;
  for (const change::RouteChange& change : report.route.changes) {
    eval::ReportedRouteChange r;
    for (const change::RouteChange::View& v : change.views) {
      if (!scored[v.pair]) continue;
      const change::AppearanceRegion& region = report.route.pairs[v.pair].appearance.regions[v.region];
      r.pairs.push_back(v.pair);
      r.boxes.push_back({region.prior_box, region.current_box});
    }
    r.confidence = change.confidence;
    reported.push_back(r);
  }
  const eval::RouteScore score = eval::ScoreRoute(truth, reported, RouteCandidates(report.route, scored), options);
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
                        {"average_precision", eval::AveragePrecision(score.ranked)},
                        {"ranked", score.ranked}};
}

// Changes of RUN (changes.json, and the grids in map.pmap) against the two flights' ground truth.
Status EvaluateChanges(const EvalArguments& arguments, const std::vector<TruthLog>& logs, nlohmann::json* report) {
  const std::string path = arguments.run + "/changes.json";
  nlohmann::json changes;
  try {
    changes = nlohmann::json::parse(std::ifstream(path));
  } catch (const nlohmann::json::exception& e) {
    return Status::DataLoss(path + ": not JSON: " + e.what());
  }
  if (changes.value("format", "") != "patrolmap.changes")
    return Status::DataLoss(path + ": not a patrolmap change report");
  const std::string prior = changes.value("prior_flight", ""), current = changes.value("current_flight", "");
  const TruthLog *prior_log = nullptr, *current_log = nullptr;
  for (const TruthLog& log : logs) {
    if (log.info.flight_id == prior) prior_log = &log;
    if (log.info.flight_id == current) current_log = &log;
  }
  if (prior_log == nullptr || current_log == nullptr) {
    return Status::InvalidArgument(path + ": compares '" + prior + "' with '" + current +
                                   "': pass both logs with --log");
  }
  std::vector<eval::TruthObject> before, after;
  PATROLMAP_RETURN_IF_ERROR(eval::ReadTruthObjects(prior_log->path, &before));
  PATROLMAP_RETURN_IF_ERROR(eval::ReadTruthObjects(current_log->path, &after));
  nlohmann::json result = {{"prior_flight", prior},
                           {"current_flight", current},
                           {"distance_m", arguments.changes.distance_m},
                           {"places_compared", changes["summary"].value("places_compared", 0)},
                           {"places_changed", changes["summary"].value("places_changed", 0)}};
  std::vector<eval::ObjectOutcome> outcomes;
  if (changes.contains("objects") && changes["objects"].is_array()) {
    std::vector<eval::ReportedObject> reported;
    PATROLMAP_RETURN_IF_ERROR(ReadReportedObjects(path, changes["objects"], &reported));
    const eval::ObjectChangeScore score = eval::ScoreObjectChanges(reported, before, after, arguments.changes);
    for (const auto& [state, counts] : score.by_state) result["objects"][state] = CountsJson(counts);
    result["objects"]["unobserved_reported"] = score.unobserved;
    result["objects"]["outcomes"] = OutcomesJson(score.outcomes, reported);
    outcomes = score.outcomes;
  }
  if (std::filesystem::exists(arguments.run + "/map.pmap")) {
    pipeline::Config config;
    graph::TopoMap map;
    change::ChangeReport recomputed;
    PATROLMAP_RETURN_IF_ERROR(LoadCheckedConfig(arguments.config, arguments.settings, &config));
    PATROLMAP_RETURN_IF_ERROR(graph::LoadMap(arguments.run + "/map.pmap", &map));
    if (!outcomes.empty()) AddSightings(map, prior, current, outcomes, before, after, &result["objects"]["outcomes"]);
    if (changes.contains("changes") && changes["changes"].is_array()) {
      std::vector<eval::ReportedEntry> entries;
      PATROLMAP_RETURN_IF_ERROR(ReadReportedEntries(path, changes["changes"], &entries));
      ScoreEntriesOf(map, prior, current, entries, before, after, arguments.changes, &result);
    }
    PATROLMAP_RETURN_IF_ERROR(pipeline::CompareFlights(map, prior, current, config.change, &recomputed));
    eval::ChangeScoreOptions options = arguments.changes;
    options.min_observations = config.change.geometry.min_observations;
    if (recomputed.geometry_compared) ScoreGeometryOf(map, recomputed, before, after, options, &result);
    ScoreAppearanceOf(map, recomputed, before, after, config.change.appearance, options, &result);
    ScoreRouteOf(map, recomputed, before, after, options, &result);
  }
  (*report)["changes"] = result;
  return Status::Ok();
}

// A score right-aligned in `width` columns, or an em dash when it has no cases (a recall with nothing to find,
// a precision with nothing reported).
std::string Score(double value, bool defined, int width) {
  char text[32];
  if (defined) {
    std::snprintf(text, sizeof(text), "%*.2f", width, value);
    return text;
  }
  return std::string(static_cast<std::size_t>(std::max(0, width - 1)), ' ') + "\u2014";
}

void PrintCounts(const char* name, const nlohmann::json& c) {
  const int tp = c["true_positives"].get<int>(), fp = c["false_positives"].get<int>();
  const int fn = c["false_negatives"].get<int>();
  std::printf("%-18s %5d %6d %7d %s %s %s\n", name, tp, fp, fn,
              Score(c["precision"].get<double>(), tp + fp > 0, 10).c_str(),
              Score(c["recall"].get<double>(), tp + fn > 0, 7).c_str(),
              Score(c["f1"].get<double>(), tp + fp > 0 && tp + fn > 0, 6).c_str());
}

void PrintChangeTable(const nlohmann::json& c) {
  std::printf("changes %s -> %s: %d places compared, %d with appearance changes\n",
              c["prior_flight"].get<std::string>().c_str(), c["current_flight"].get<std::string>().c_str(),
              c["places_compared"].get<int>(), c["places_changed"].get<int>());
  std::printf("%-18s %5s %6s %7s %10s %7s %6s\n", "", "true", "false", "missed", "precision", "recall", "F1");
  if (c.contains("objects")) {
    for (const char* state : {"new", "removed", "moved", "persistent"}) {
      PrintCounts((std::string("objects ") + state).c_str(), c["objects"][state]);
    }
  }
  if (c.contains("appearance")) {
    const nlohmann::json& a = c["appearance"];
    const double p = a["precision"].get<double>(), r = a["recall"].get<double>();
    const int regions = a["regions"].get<int>(), changes = a["changes"].get<int>();
    std::printf("%-18s %5d %6d %7d %s %s %s\n", "appearance regions", a["regions_on_change"].get<int>(),
                regions - a["regions_on_change"].get<int>(), changes - a["changes_found"].get<int>(),
                Score(p, regions > 0, 10).c_str(), Score(r, changes > 0, 7).c_str(),
                Score(p + r > 0 ? 2 * p * r / (p + r) : 0.0, regions > 0 && changes > 0, 6).c_str());
    std::printf("appearance: %d regions, %d object changes visible in the key frames of %d registered places\n",
                regions, changes, a["places"].get<int>());
  }
  if (c.contains("route")) {
    const nlohmann::json& r = c["route"];
    const int changes = r["changes"].get<int>(), visible = r["visible"].get<int>();
    std::printf(
        "route: %d of %d frames compared (%.0f %%); %d changes, %d on an object change (precision %s), "
        "%d of %d visible object changes found (recall %s)\n",
        r["pairs"].get<int>(), r["frames"].get<int>(), 100.0 * r["compared_share"].get<double>(), changes,
        r["changes_on_change"].get<int>(), Score(r["precision"].get<double>(), changes > 0, 0).c_str(),
        r["found"].get<int>(), visible, Score(r["recall"].get<double>(), visible > 0, 0).c_str());
    std::printf("route: of those in a prior frame (objects that left, places a moved one left): %d of %d found\n",
                r["found_in_prior"].get<int>(), r["visible_in_prior"].get<int>());
    if (r.contains("lost_at") && !r["lost_at"].empty()) {
      std::string lost;
      for (const auto& [step, count] : r["lost_at"].items())
        lost += (lost.empty() ? "" : ", ") + step + " " + std::to_string(count.get<int>());
      std::printf("route: the changes not found were lost at: %s\n", lost.c_str());
    }
  }
  if (c.contains("entries")) {
    const nlohmann::json& e = c["entries"];
    const int placed = e["entries"].get<int>() - e["bearings"].get<int>();
    std::printf(
        "change list: %d entries (%d by a bearing only), %d of %d placed on a true change (precision %s); found %d of "
        "%d true changes (recall %s, F1 %s), %d of %d observable ones (recall %s, F1 %s)\n",
        e["entries"].get<int>(), e["bearings"].get<int>(), e["true_entries"].get<int>(), placed,
        Score(e["precision"].get<double>(), placed > 0, 0).c_str(), e["found"].get<int>(), e["true_changes"].get<int>(),
        Score(e["recall"].get<double>(), e["true_changes"].get<int>() > 0, 0).c_str(),
        Score(e["f1"].get<double>(), placed > 0, 0).c_str(), e["observable_found"].get<int>(),
        e["observable"].get<int>(),
        Score(e["recall_observable"].get<double>(), e["observable"].get<int>() > 0, 0).c_str(),
        Score(e["f1_observable"].get<double>(), placed > 0, 0).c_str());
  }
  if (c.contains("geometry")) {
    PrintCounts("voxels", c["geometry"]);
    std::printf("geometry: IoU %.2f over %lld voxels observed in both flights, %d regions\n",
                c["geometry"]["iou"].get<double>(), c["geometry"]["observed_voxels"].get<long long>(),
                c["geometry"]["regions"].get<int>());
    std::printf(
        "geometry: %lld of the false voxels lie within %.2g m of an object that changed (a change reported "
        "too wide)\n",
        c["geometry"]["false_positives_near_change"].get<long long>(), c["geometry"]["near_change_m"].get<double>());
  }
}

void PrintTables(const nlohmann::json& report) {
  if (report.contains("key_locations")) {
    const nlohmann::json& k = report["key_locations"];
    std::printf("key locations (paper 002 Table II), tolerance %.2f s\n", k["tolerance_s"].get<double>());
    std::printf("%-20s %8s %6s %9s %5s %6s %7s %10s %7s\n", "flight", "frames", "nodes", "expected", "true", "false",
                "missed", "precision", "recall");
    std::printf("%-20s %8lld %6d %9d %5d %6d %7d %s %s\n", k["flight"].get<std::string>().c_str(),
                k["frames"].get<long long>(), k["nodes"].get<int>(), k["expected"].get<int>(),
                k["true_positives"].get<int>(), k["false_positives"].get<int>(), k["missed"].get<int>(),
                Score(k["precision"].get<double>(), k["nodes"].get<int>() > 0, 10).c_str(),
                Score(k["recall"].get<double>(), k["expected"].get<int>() > 0, 7).c_str());
  }
  if (report.contains("loop_closures")) {
    const nlohmann::json& l = report["loop_closures"];
    std::printf("loop closures (paper 002 Table III), same place within %.1f m and %.0f deg\n",
                l["radius_m"].get<double>(), l["max_heading_deg"].get<double>());
    std::printf("%6s %9s %6s %9s %6s %10s %7s\n", "nodes", "possible", "found", "reported", "false", "precision",
                "recall");
    std::printf("%6d %9d %6d %9d %6d %s %s\n", l["nodes"].get<int>(), l["possible"].get<int>(), l["found"].get<int>(),
                l["reported"].get<int>(), l["false_positives"].get<int>(),
                Score(l["precision"].get<double>(), l["reported"].get<int>() > 0, 10).c_str(),
                Score(l["recall"].get<double>(), l["possible"].get<int>() > 0, 7).c_str());
  }
  if (report.contains("changes")) PrintChangeTable(report["changes"]);
}

Status Evaluate(const EvalArguments& arguments, nlohmann::json* report) {
  const bool has_key_locations = std::filesystem::exists(arguments.run + "/key_locations.csv");
  const bool has_loop_closures = std::filesystem::exists(arguments.run + "/loop_closures.csv");
  const bool has_changes = std::filesystem::exists(arguments.run + "/changes.json");
  if (!has_key_locations && !has_loop_closures && !has_changes) {
    return Status::NotFound(arguments.run + ": holds none of key_locations.csv, loop_closures.csv, changes.json");
  }
  std::vector<TruthLog> logs(arguments.logs.size());
  for (std::size_t i = 0; i < logs.size(); ++i) {
    PATROLMAP_RETURN_IF_ERROR(LoadTruthLog(arguments.logs[i], has_loop_closures, &logs[i]));
  }
  *report = {{"schema", "patrolmap.eval/1"}, {"run", arguments.run}};
  if (has_key_locations) PATROLMAP_RETURN_IF_ERROR(EvaluateKeyLocations(arguments, logs.front(), report));
  if (has_loop_closures) PATROLMAP_RETURN_IF_ERROR(EvaluateLoopClosures(arguments, logs, report));
  if (has_changes) PATROLMAP_RETURN_IF_ERROR(EvaluateChanges(arguments, logs, report));
  return Status::Ok();
}

int RunEval(const EvalArguments& arguments) {
  nlohmann::json report;
  const Status status = Evaluate(arguments, &report);
  if (!status.ok()) {
    spdlog::error("{}", status.message());
    return 1;
  }
  if (arguments.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    PrintTables(report);
  }
  return 0;
}

}  // namespace

Command AddEvalCommand(CLI::App* app) {
  auto arguments = std::make_shared<EvalArguments>();
  app->add_option("run", arguments->run, "output folder of a run (key_locations.csv; nodes.csv + loop_closures.csv)")
      ->required();
  app->add_option("--log", arguments->logs,
                  "simulated log(s) the run processed (with groundtruth/); key locations "
                  "are scored against the first")
      ->required();
  app->add_flag("--json", arguments->json, "print JSON (schema patrolmap.eval/1) instead of tables");
  app->add_flag("-v,--verbose", arguments->verbose, "list every expected key-location span and its match");
  app->add_option("--tolerance", arguments->key_locations.tolerance_s, "key locations: slack around each span [s]")
      ->check(FiniteRange(0.0, 3600.0))
      ->capture_default_str();
  app->add_option("--min-span", arguments->key_locations.min_span_s,
                  "key locations: passages and facades shorter than this merge into their neighbours [s]")
      ->check(FiniteRange(0.0, 3600.0))
      ->capture_default_str();
  app->add_option("--radius", arguments->loop_closures.radius_m, "loop closures: same place within this distance [m]")
      ->check(FiniteRange(1e-3, 1e6))
      ->capture_default_str();
  app->add_option("--max-heading", arguments->loop_closures.max_heading_deg,
                  "loop closures: and this heading difference [deg]")
      ->check(FiniteRange(0.0, 180.0))
      ->capture_default_str();
  app->add_option("--min-gap", arguments->loop_closures.min_gap_s,
                  "loop closures: nodes of one flight closer in time are neighbours [s]")
      ->check(FiniteRange(0.0, 1e6))
      ->capture_default_str();
  app->add_option("--change-distance", arguments->changes.distance_m,
                  "changes: a reported object is a hit within this distance of a true one of its state and label [m]")
      ->check(FiniteRange(1e-3, 1e6))
      ->capture_default_str();
  app->add_option("--min-detections", arguments->changes.min_detections,
                  "changes: true objects the detector reported fewer times in a flight do not count")
      ->capture_default_str();
  app->add_option("-c,--config", arguments->config, "the run's configuration (change.* keys), for the geometry score");
  AddSetOption(app, &arguments->settings);
  return [arguments] { return RunEval(*arguments); };
}

}  // namespace patrolmap::tools
