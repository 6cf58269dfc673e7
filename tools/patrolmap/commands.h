// Subcommands of the patrolmap command line. Each registers its options on
// the app and returns the exit code when run: 0 success, 1 bad input or a
// failed run (the message names the file and the problem), 2 bad usage.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace patrolmap::tools {

using Command = std::function<int()>;

Command AddDetectCommand(CLI::App* app);
Command AddSimulateCommand(CLI::App* app);
Command AddEvalCommand(CLI::App* app);
Command AddMapCommand(CLI::App* app);
Command AddVocabCommand(CLI::App* app);
Command AddPatrolCommand(CLI::App* app);
Command AddInfoCommand(CLI::App* app);
Command AddExportCommand(CLI::App* app);
Command AddDiffCommand(CLI::App* app);
Command AddMergeCommand(CLI::App* app);
Command AddHistoryCommand(CLI::App* app);

}  // namespace patrolmap::tools
