// patrolmap: topological appearance mapping for UAV patrols (offline front end).
#include <map>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{"patrolmap: key locations from optical flow, topological maps and change detection for UAV patrols"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "patrolmap 0.1.0");
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "only print errors");
  std::map<CLI::App*, patrolmap::tools::Command> commands;
  const auto add = [&](const char* name, const char* help, auto adder) {
    CLI::App* sub = app.add_subcommand(name, help);
    commands[sub] = adder(sub);
  };
  add("detect", "detect key locations in a flight log (paper 002 III-A)", patrolmap::tools::AddDetectCommand);
  add("simulate", "render a simulated flight log with ground truth", patrolmap::tools::AddSimulateCommand);
  add("map", "detect key locations and close loops between them (paper 002 III)", patrolmap::tools::AddMapCommand);
  add("patrol", "add a later flight to a map, closing loops against every earlier flight",
      patrolmap::tools::AddPatrolCommand);
  add("info", "summarise a map file, or list a ROS bag's topics", patrolmap::tools::AddInfoCommand);
  add("diff", "report what changed between two flights of a map", patrolmap::tools::AddDiffCommand);
  add("export", "write a map as GraphML, DOT or JSON", patrolmap::tools::AddExportCommand);
  add("vocab", "vocabulary tools: vocab build", patrolmap::tools::AddVocabCommand);
  add("eval", "score a run against a simulated log's ground truth", patrolmap::tools::AddEvalCommand);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  }
  spdlog::set_default_logger(spdlog::stderr_logger_mt("patrolmap"));  // results on stdout, messages on stderr
  spdlog::set_pattern("%l: %v");
  spdlog::set_level(quiet ? spdlog::level::err : spdlog::level::info);
  for (const auto& [sub, command] : commands) {
    if (sub->parsed()) return command();
  }
  return 2;
}
