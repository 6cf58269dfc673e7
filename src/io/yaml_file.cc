#include "patrolmap/io/yaml_file.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace patrolmap::io {
namespace {

// Checks the keys of every map in `node` (at any depth): each must be a plain name (patrolmap's files use
// no other kind), and none may appear twice in one map (YAML forbids it, and yaml-cpp would keep one
// silently). Returns the problem and fills `line` (1-based), or returns "" when the keys are fine.
std::string CheckKeys(const YAML::Node& node, int* line) {
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) {
      std::string problem = CheckKeys(item, line);
      if (!problem.empty()) return problem;
    }
  }
  if (!node.IsMap()) return "";
  std::set<std::string> keys;
  for (const auto& pair : node) {
    *line = pair.first.Mark().line + 1;
    if (!pair.first.IsScalar()) return "a key must be a plain name, not a map or a list";
    if (!keys.insert(pair.first.Scalar()).second) return "key '" + pair.first.Scalar() + "' appears twice in one map";
    std::string problem = CheckKeys(pair.second, line);
    if (!problem.empty()) return problem;
  }
  return "";
}

}  // namespace

Status LoadYamlFile(const std::string& path, YAML::Node* root) {
  if (!std::filesystem::is_regular_file(path)) return Status::NotFound(path + ": no such file");
  std::ifstream stream(path);
  if (!stream) return Status::IoError(path + ": cannot open for reading");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  std::string text = buffer.str();
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';  // keep line numbers intact
  try {
    *root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    return Status::DataLoss(path + ":" + std::to_string(error.mark.line + 1) + ": " + error.msg);
  }
  int line = 0;
  const std::string problem = CheckKeys(*root, &line);
  if (!problem.empty()) return Status::DataLoss(path + ":" + std::to_string(line) + ": " + problem);
  return Status::Ok();
}

Status LoadYamlMap(const std::string& path, YAML::Node* root) {
  PATROLMAP_RETURN_IF_ERROR(LoadYamlFile(path, root));
  if (root->IsNull()) *root = YAML::Node(YAML::NodeType::Map);  // an empty file: no keys
  if (!root->IsMap()) return Status::DataLoss(path + ": expected a map of keys at the top level");
  return Status::Ok();
}

}  // namespace patrolmap::io
