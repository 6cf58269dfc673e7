#include "patrolmap/io/yaml_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace patrolmap::io {

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
  return Status::Ok();
}

Status LoadYamlMap(const std::string& path, YAML::Node* root) {
  PATROLMAP_RETURN_IF_ERROR(LoadYamlFile(path, root));
  if (root->IsNull()) *root = YAML::Node(YAML::NodeType::Map);  // an empty file: no keys
  if (!root->IsMap()) return Status::DataLoss(path + ": expected a map of keys at the top level");
  return Status::Ok();
}

}  // namespace patrolmap::io
