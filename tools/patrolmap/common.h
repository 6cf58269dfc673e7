// Helpers the subcommands share.
#pragma once

#include <string>

#include <spdlog/spdlog.h>

#include "patrolmap/core/status.h"
#include "patrolmap/pipeline/config.h"

namespace patrolmap::tools {

// Logs the status and returns the exit code for it (1: bad input or failed run).
inline int Fail(const Status& status) {
  spdlog::error("{}", status.message());
  return 1;
}

// Loads `path` over the defaults (none: defaults only) and checks the result.
inline Status LoadCheckedConfig(const std::string& path, pipeline::Config* config) {
  if (!path.empty()) PATROLMAP_RETURN_IF_ERROR(pipeline::LoadConfig(path, config));
  std::string error;
  if (!config->IsValid(&error)) return Status::InvalidArgument(error);
  return Status::Ok();
}

}  // namespace patrolmap::tools
