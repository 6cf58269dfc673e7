// Helpers the subcommands share.
#pragma once

#include <string>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "../cli_checks.h"
#include "patrolmap/change/report.h"
#include "patrolmap/core/status.h"
#include "patrolmap/pipeline/config.h"

namespace patrolmap::tools {

// Logs the status and returns the exit code for it (1: bad input or failed run).
inline int Fail(const Status& status) {
  spdlog::error("{}", status.message());
  return 1;
}

using pipeline::LoadCheckedConfig;

using tools::FiniteRange;

// --fps: the frame rate of image folders, patterns and videos, overriding their own times [Hz].
void AddFpsOption(CLI::App* app, double* fps);

// --topic ROLE=NAME (repeatable): the topics of a ROS bag the flight is read from.
void AddTopicOption(CLI::App* app, std::vector<std::string>* topics);

// --poses: the camera poses of the log from a TUM or KITTI pose file (change detection needs them).
void AddPosesOption(CLI::App* app, std::string* poses);

// --camera: the camera's calibration for logs without one (image folders and patterns), as a EuRoC sensor.yaml.
void AddCameraOption(CLI::App* app, std::string* camera);

// Prints one line on what changed between the report's flights (diff and patrol).
void PrintChangeSummary(const change::ChangeReport& report, const std::string& out);

}  // namespace patrolmap::tools
