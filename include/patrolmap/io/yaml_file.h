// Loading YAML files with errors that name the file and line.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "patrolmap/core/status.h"

namespace patrolmap::io {

// Parses `path`. A leading OpenCV-style "%YAML:1.0" directive (found in EuRoC's
// sensor.yaml files, and not valid YAML) is ignored.
Status LoadYamlFile(const std::string& path, YAML::Node* root);

// As LoadYamlFile, for files that must hold a map of keys (sensor.yaml, meta.yaml): anything else at the
// top level fails naming the file; an empty file is an empty map.
Status LoadYamlMap(const std::string& path, YAML::Node* root);

}  // namespace patrolmap::io
