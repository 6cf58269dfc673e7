// patrolmap eval RUN --log LOG [--log LOG ...] [--json] [--tolerance S] [--min-span S] [--radius M] ...
#include <cstdio>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "patrolmap/eval/run_score.h"

namespace patrolmap::tools {
namespace {

struct EvalArguments {
  std::string run;
  std::vector<std::string> logs;
  bool json = false;
  bool verbose = false;
  eval::RunScoreOptions scores;
  std::string config;
  std::vector<std::string> settings;  // --set KEY=VALUE
};

int RunEval(EvalArguments arguments) {
  pipeline::Config config;
  nlohmann::json report;
  Status status = LoadCheckedConfig(arguments.config, arguments.settings, &config);
  arguments.scores.change = pipeline::ChangeOptionsOf(config);
  if (status.ok()) status = eval::ScoreRun(arguments.run, arguments.logs, arguments.scores, &report);
  if (!status.ok()) {
    spdlog::error("{}", status.message());
    return 1;
  }
  if (arguments.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::fputs(eval::RunScoreTables(report, arguments.verbose).c_str(), stdout);
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
  app->add_option("--tolerance", arguments->scores.key_locations.tolerance_s,
                  "key locations: slack around each span [s]")
      ->check(FiniteRange(0.0, 3600.0))
      ->capture_default_str();
  app->add_option("--min-span", arguments->scores.key_locations.min_span_s,
                  "key locations: passages and facades shorter than this merge into their neighbours [s]")
      ->check(FiniteRange(0.0, 3600.0))
      ->capture_default_str();
  app->add_option("--radius", arguments->scores.loop_closures.radius_m,
                  "loop closures: same place within this distance [m]")
      ->check(FiniteRange(1e-3, 1e6))
      ->capture_default_str();
  app->add_option("--max-heading", arguments->scores.loop_closures.max_heading_deg,
                  "loop closures: and this heading difference [deg]")
      ->check(FiniteRange(0.0, 180.0))
      ->capture_default_str();
  app->add_option("--min-gap", arguments->scores.loop_closures.min_gap_s,
                  "loop closures: nodes of one flight closer in time are neighbours [s]")
      ->check(FiniteRange(0.0, 1e6))
      ->capture_default_str();
  app->add_option("--change-distance", arguments->scores.changes.distance_m,
                  "changes: a reported object is a hit within this distance of a true one of its state and label [m]")
      ->check(FiniteRange(1e-3, 1e6))
      ->capture_default_str();
  app->add_option("--min-detections", arguments->scores.changes.min_detections,
                  "changes: true objects the detector reported fewer times in a flight do not count")
      ->capture_default_str();
  app->add_option("-c,--config", arguments->config, "the run's configuration (change.* keys), for the geometry score");
  AddSetOption(app, &arguments->settings);
  return [arguments] { return RunEval(*arguments); };
}

}  // namespace patrolmap::tools
