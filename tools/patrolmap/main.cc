// patrolmap: topological appearance mapping for UAV patrols (offline front end).
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"

namespace {

// Edits (insertions, deletions, substitutions, swaps of neighbours) that turn `a` into `b`.
std::size_t Distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// A first argument that is neither an option nor a command is named, with the nearest command.
bool UnknownCommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return false;
  const std::string word = argv[1];
  std::string nearest, names;
  std::size_t best = 3;  // suggest only a command at most two edits away
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub->get_name() == word) return false;
    names += (names.empty() ? "" : ", ") + sub->get_name();
    const std::size_t distance = Distance(word, sub->get_name());
    if (distance < best) best = distance, nearest = sub->get_name();
  }
  std::fprintf(stderr, "patrolmap: '%s' is not a command%s\ncommands: %s (patrolmap COMMAND --help for each)\n",
               word.c_str(), nearest.empty() ? "" : ("; did you mean '" + nearest + "'?").c_str(), names.c_str());
  return true;
}

}  // namespace

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
  add("vocab", "vocabulary tools: vocab build", patrolmap::tools::AddVocabCommand);
  add("eval", "score a run against a simulated log's ground truth", patrolmap::tools::AddEvalCommand);
  if (UnknownCommand(app, argc, argv)) return 2;
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
