// patrolmap eval RUN_DIR --log LOG [--json] [--tolerance S]
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/io/readers.h"

namespace patrolmap::tools {
namespace {

struct EvalArguments {
  std::string run;
  std::string log;
  bool json = false;
  bool verbose = false;
  double tolerance_s = 1.0;
  double min_span_s = 2.0;
};

nlohmann::json ScoreJson(const eval::KeyLocationScore& score, double tolerance_s, double min_span_s) {
  return {{"tolerance_s", tolerance_s},       {"min_span_s", min_span_s}, {"nodes", score.detected},
          {"expected", score.expected},       {"true_positives", score.true_positives},
          {"false_positives", score.false_positives}, {"missed", score.missed},
          {"precision", score.precision()},   {"recall", score.recall()}};
}

void PrintTable(const io::LogInfo& info, const eval::KeyLocationScore& score, double tolerance_s) {
  std::printf("key locations (paper 002 Table II), tolerance %.2f s\n", tolerance_s);
  std::printf("%-20s %8s %6s %9s %5s %6s %7s %10s %7s\n", "flight", "frames", "nodes", "expected", "true", "false",
              "missed", "precision", "recall");
  std::printf("%-20s %8lld %6d %9d %5d %6d %7d %10.2f %7.2f\n", info.flight_id.c_str(),
              static_cast<long long>(info.frame_count), score.detected, score.expected, score.true_positives,
              score.false_positives, score.missed, score.precision(), score.recall());
}

void PrintSpans(const eval::KeyLocationScore& score, const std::vector<KeyLocation>& detected) {
  for (std::size_t i = 0; i < score.spans.size(); ++i) {
    const eval::ExpectedSpan& span = score.spans[i];
    const int match = score.span_match[i];
    std::printf("  span %6.2f .. %6.2f s  %-6s %-8s -> %s\n", span.start_s, span.end_s, ToString(span.kind),
                span.required ? "required" : "optional",
                match >= 0 ? ("node " + std::to_string(detected[match].node_index)).c_str() : "-");
  }
  for (std::size_t d = 0; d < detected.size(); ++d) {
    if (score.verdicts[d] == eval::Verdict::kFalsePositive) {
      std::printf("  false: node %d at %.2f s (%s)\n", detected[d].node_index, NsToSeconds(detected[d].timestamp_ns),
                  ToString(detected[d].kind));
    }
  }
}

int RunEval(const EvalArguments& arguments) {
  std::vector<KeyLocation> detected;
  std::vector<eval::TruthEdge> edges;
  std::unique_ptr<io::FrameSource> source;
  Status status = eval::ReadKeyLocationsCsv(arguments.run + "/key_locations.csv", &detected);
  if (status.ok()) status = eval::ReadTruthEdges(arguments.log, &edges);
  if (status.ok()) status = io::OpenLog(arguments.log, {}, &source);
  if (!status.ok()) {
    spdlog::error("{}", status.message());
    return 1;
  }
  const eval::KeyLocationScore score =
      eval::ScoreKeyLocations(detected, edges, {arguments.tolerance_s, arguments.min_span_s});
  if (arguments.json) {
    const nlohmann::json report = {{"schema", "patrolmap.eval/1"},
                                   {"flight", source->info().flight_id},
                                   {"frames", source->info().frame_count},
                                   {"key_locations", ScoreJson(score, arguments.tolerance_s, arguments.min_span_s)}};
    std::printf("%s\n", report.dump(2).c_str());
    return 0;
  }
  PrintTable(source->info(), score, arguments.tolerance_s);
  if (arguments.verbose) PrintSpans(score, detected);
  return 0;
}

}  // namespace

Command AddEvalCommand(CLI::App* app) {
  auto arguments = std::make_shared<EvalArguments>();
  app->add_option("run", arguments->run, "output folder of a run (holds key_locations.csv)")->required();
  app->add_option("--log", arguments->log, "the simulated log the run processed (holds groundtruth/)")->required();
  app->add_flag("--json", arguments->json, "print JSON instead of a table");
  app->add_flag("-v,--verbose", arguments->verbose, "list every expected span and every false node");
  app->add_option("--tolerance", arguments->tolerance_s, "slack around each expected span [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--min-span", arguments->min_span_s,
                  "passages and facades shorter than this merge into their neighbours [s]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return [arguments] { return RunEval(*arguments); };
}

}  // namespace patrolmap::tools
