// patrolmap: topological appearance mapping for UAV patrols (offline front end).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/nearest_name.h"
#include "progress.h"

namespace {

// A first argument that is neither an option nor a command is named, with the nearest command.
bool UnknownCommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return false;
  const std::string word = argv[1];
  std::string nearest, names;
  std::size_t best = 3;  // suggest only a command at most two edits away
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub->get_name() == word) return false;
    names += (names.empty() ? "" : ", ") + sub->get_name();
    const std::size_t distance = patrolmap::EditDistance(word, sub->get_name());
    if (distance < best) best = distance, nearest = sub->get_name();
  }
  std::fprintf(stderr, "patrolmap: '%s' is not a command%s\ncommands: %s (patrolmap COMMAND --help for each)\n",
               word.c_str(), nearest.empty() ? "" : ("; did you mean '" + nearest + "'?").c_str(), names.c_str());
  return true;
}

// The long names ("--out") of the options `app` takes.
std::vector<std::string> LongNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  return names;
}

// A long option that the chosen command does not take is named, with the nearest one it does take, before CLI11
// reads the line (its own message for "--mpa foo" counts positional arguments instead).
bool UnknownOption(CLI::App& app, int argc, char** argv) {
  CLI::App* command = &app;
  int i = 1;
  for (; i < argc; ++i) {
    const std::vector<CLI::App*> subs =
        command->get_subcommands([&](const CLI::App* sub) { return sub->get_name() == argv[i]; });
    if (subs.empty()) break;
    command = subs.front();
  }
  if (command == &app) return false;
  std::vector<std::string> names = LongNames(*command), global = LongNames(app);
  names.insert(names.end(), global.begin(), global.end());
  for (; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    if (word.size() < 3 || word.compare(0, 2, "--") != 0) continue;
    const std::string name = word.substr(0, word.find('='));
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    std::fprintf(stderr, "patrolmap %s: unknown option '%s'%s\n(patrolmap %s --help lists its options)\n",
                 command->get_name().c_str(), name.c_str(), patrolmap::DidYouMean(name, names).c_str(),
                 command->get_name().c_str());
    return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  patrolmap::RemoveTemporariesOnSignal();  // an interrupted save leaves no map.pmap.tmp.PID behind
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
  add("detect", "find the key locations of a flight log, where the scene opens and closes (paper 002 III-A)",
      patrolmap::tools::AddDetectCommand);
  add("simulate", "render a simulated flight log with ground truth", patrolmap::tools::AddSimulateCommand);
  add("map",
      "build a map from flight logs: key locations become nodes, places seen again become loop closures (paper 002 "
      "III)",
      patrolmap::tools::AddMapCommand);
  add("patrol", "fly a later patrol against a map: add it, recognise the places seen before, and report what changed",
      patrolmap::tools::AddPatrolCommand);
  add("merge",
      "merge maps built apart (a fleet's logs mapped on several machines) into one, with the loop closures "
      "between them",
      patrolmap::tools::AddMergeCommand);
  add("info", "summarise a map file, or list a ROS bag's topics", patrolmap::tools::AddInfoCommand);
  add("diff", "report what changed between two flights of a map (a page with pictures and a plan, JSON, GeoJSON, KML)",
      patrolmap::tools::AddDiffCommand);
  add("export", "write a map for other tools: GraphML, DOT, JSON, SVG, an HTML viewer, GeoJSON or KML",
      patrolmap::tools::AddExportCommand);
  add("history", "the site's objects over the map's patrols: first seen, moved, gone, back",
      patrolmap::tools::AddHistoryCommand);
  add("vocab", "vocabulary tools: vocab build", patrolmap::tools::AddVocabCommand);
  add("eval", "score a run against a simulated log's ground truth", patrolmap::tools::AddEvalCommand);
  if (UnknownCommand(app, argc, argv) || UnknownOption(app, argc, argv)) return 2;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : 2;
  }
  // Results on stdout, messages on stderr.
  spdlog::set_default_logger(
      std::make_shared<spdlog::logger>("patrolmap", std::make_shared<patrolmap::tools::ProgressAwareSink>()));
  spdlog::set_pattern("%l: %v");
  spdlog::set_level(quiet ? spdlog::level::err : spdlog::level::info);
  for (const auto& [sub, command] : commands) {
    if (!sub->parsed()) continue;
    // Input errors are Status values; what a library still throws (a file system that refuses a name, memory
    // that runs out for a huge request) ends the command with its message, never an abort.
    try {
      return command();
    } catch (const std::bad_alloc&) {
      spdlog::error("patrolmap {}: out of memory (a resolution, count or file larger than this machine holds?)",
                    sub->get_name());
    } catch (const std::exception& error) {
      spdlog::error("patrolmap {}: {}", sub->get_name(), error.what());
    }
    return 1;
  }
  return 2;
}
