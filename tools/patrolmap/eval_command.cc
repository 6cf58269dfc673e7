// patrolmap eval RUN --log LOG [--log LOG ...] [--json] [--tolerance S] [--min-span S] [--radius M] ...
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/eval/loop_closure_score.h"
#include "patrolmap/io/readers.h"

namespace patrolmap::tools {
namespace {

struct EvalArguments {
  std::string run;
  std::vector<std::string> logs;
  bool json = false;
  bool verbose = false;
  eval::KeyLocationScoreOptions key_locations;
  eval::LoopClosureScoreOptions loop_closures;
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
  (*report)["key_locations"] = {
      {"flight", log.info.flight_id},          {"frames", log.info.frame_count},
      {"tolerance_s", arguments.key_locations.tolerance_s}, {"min_span_s", arguments.key_locations.min_span_s},
      {"nodes", score.detected},               {"expected", score.expected},
      {"true_positives", score.true_positives}, {"false_positives", score.false_positives},
      {"missed", score.missed},                {"precision", score.precision()},
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
    if (log == by_flight.end()) return Status::InvalidArgument(arguments.run + "/nodes.csv: node " + std::to_string(node.node) + " comes from flight '" + node.flight + "', which no --log holds");
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

void PrintTables(const nlohmann::json& report) {
  if (report.contains("key_locations")) {
    const nlohmann::json& k = report["key_locations"];
    std::printf("key locations (paper 002 Table II), tolerance %.2f s\n", k["tolerance_s"].get<double>());
    std::printf("%-20s %8s %6s %9s %5s %6s %7s %10s %7s\n", "flight", "frames", "nodes", "expected", "true", "false",
                "missed", "precision", "recall");
    std::printf("%-20s %8lld %6d %9d %5d %6d %7d %10.2f %7.2f\n", k["flight"].get<std::string>().c_str(),
                k["frames"].get<long long>(), k["nodes"].get<int>(), k["expected"].get<int>(),
                k["true_positives"].get<int>(), k["false_positives"].get<int>(), k["missed"].get<int>(),
                k["precision"].get<double>(), k["recall"].get<double>());
  }
  if (report.contains("loop_closures")) {
    const nlohmann::json& l = report["loop_closures"];
    std::printf("loop closures (paper 002 Table III), same place within %.1f m and %.0f deg\n",
                l["radius_m"].get<double>(), l["max_heading_deg"].get<double>());
    std::printf("%6s %9s %6s %9s %6s %10s %7s\n", "nodes", "possible", "found", "reported", "false", "precision",
                "recall");
    std::printf("%6d %9d %6d %9d %6d %10.2f %7.2f\n", l["nodes"].get<int>(), l["possible"].get<int>(),
                l["found"].get<int>(), l["reported"].get<int>(), l["false_positives"].get<int>(),
                l["precision"].get<double>(), l["recall"].get<double>());
  }
}

Status Evaluate(const EvalArguments& arguments, nlohmann::json* report) {
  const bool has_key_locations = std::filesystem::exists(arguments.run + "/key_locations.csv");
  const bool has_loop_closures = std::filesystem::exists(arguments.run + "/loop_closures.csv");
  if (!has_key_locations && !has_loop_closures) {
    return Status::NotFound(arguments.run + ": holds neither key_locations.csv nor loop_closures.csv");
  }
  std::vector<TruthLog> logs(arguments.logs.size());
  for (std::size_t i = 0; i < logs.size(); ++i) {
    PATROLMAP_RETURN_IF_ERROR(LoadTruthLog(arguments.logs[i], has_loop_closures, &logs[i]));
  }
  *report = {{"schema", "patrolmap.eval/1"}, {"run", arguments.run}};
  if (has_key_locations) PATROLMAP_RETURN_IF_ERROR(EvaluateKeyLocations(arguments, logs.front(), report));
  if (has_loop_closures) PATROLMAP_RETURN_IF_ERROR(EvaluateLoopClosures(arguments, logs, report));
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
  app->add_option("--log", arguments->logs, "simulated log(s) the run processed (with groundtruth/); key locations "
                  "are scored against the first")
      ->required();
  app->add_flag("--json", arguments->json, "print JSON (schema patrolmap.eval/1) instead of tables");
  app->add_flag("-v,--verbose", arguments->verbose, "list every expected key-location span and its match");
  app->add_option("--tolerance", arguments->key_locations.tolerance_s, "key locations: slack around each span [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--min-span", arguments->key_locations.min_span_s,
                  "key locations: passages and facades shorter than this merge into their neighbours [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--radius", arguments->loop_closures.radius_m, "loop closures: same place within this distance [m]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--max-heading", arguments->loop_closures.max_heading_deg,
                  "loop closures: and this heading difference [deg]")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  app->add_option("--min-gap", arguments->loop_closures.min_gap_s,
                  "loop closures: nodes of one flight closer in time are neighbours [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return [arguments] { return RunEval(*arguments); };
}

}  // namespace patrolmap::tools
