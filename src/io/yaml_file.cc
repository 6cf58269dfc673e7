#include "patrolmap/io/yaml_file.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace patrolmap::io {
namespace {

// Finds a key that a map of `node` (at any depth) holds twice: YAML forbids it, and yaml-cpp would keep
// one of the two silently. Fills `key` and `line` (1-based) and returns true when there is one.
bool FindRepeatedKey(const YAML::Node& node, std::string* key, int* line) {
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) {
      if (FindRepeatedKey(item, key, line)) return true;
    }
  }
  if (!node.IsMap()) return false;
  std::set<std::string> keys;
  for (const auto& pair : node) {
    if (pair.first.IsScalar() && !keys.insert(pair.first.Scalar()).second) {
      *key = pair.first.Scalar();
      *line = pair.first.Mark().line + 1;
      return true;
    }
    if (FindRepeatedKey(pair.second, key, line)) return true;
  }
  return false;
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
  std::string key;
  int line = 0;
  if (FindRepeatedKey(*root, &key, &line)) {
    return Status::DataLoss(path + ":" + std::to_string(line) + ": key '" + key + "' appears twice in one map");
  }
  return Status::Ok();
}

Status LoadYamlMap(const std::string& path, YAML::Node* root) {
  PATROLMAP_RETURN_IF_ERROR(LoadYamlFile(path, root));
  if (root->IsNull()) *root = YAML::Node(YAML::NodeType::Map);  // an empty file: no keys
  if (!root->IsMap()) return Status::DataLoss(path + ": expected a map of keys at the top level");
  return Status::Ok();
}

}  // namespace patrolmap::io
