#include "patrolmap/pipeline/config.h"

#include <algorithm>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "patrolmap/core/nearest_name.h"
#include "patrolmap/core/option_check.h"
#include "patrolmap/io/yaml_file.h"

namespace patrolmap::pipeline {
namespace {

std::vector<std::string> SplitPath(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream stream(path);
  for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
  return parts;
}

// Reads each visited field from a parsed YAML tree.
class YamlReader {
 public:
  YamlReader(std::string file, YAML::Node root) : file_(std::move(file)), root_(std::move(root)) {}

  template <typename T>
  void Field(const std::string& path, T* value) {
    known_.insert(path);
    if (!status_.ok()) return;
    const YAML::Node node = Find(path);
    if (node) Parse(path, node, value);
  }

  // Fails on keys of the file that no field claimed.
  void CheckUnknown(const YAML::Node& node, const std::string& prefix) {
    if (!status_.ok() || !node.IsMap()) return;
    for (const auto& item : node) {
      const std::string path =
          prefix.empty() ? item.first.as<std::string>() : prefix + "." + item.first.as<std::string>();
      if (known_.count(path) != 0) continue;
      if (item.second.IsMap() && IsSection(path)) {
        CheckUnknown(item.second, path);
        continue;
      }
      Fail(path, item.first, "unknown key" + DidYouMean(path, KnownAtDepthOf(path)));
      return;
    }
  }

  const Status& status() const { return status_; }

 private:
  // The known keys and sections as deep as `path` ("flow.smoothing" for "flow.smothing"), to suggest one.
  std::vector<std::string> KnownAtDepthOf(const std::string& path) const {
    const std::size_t depth = SplitPath(path).size();
    std::set<std::string> names;
    for (const std::string& key : known_) {
      const std::vector<std::string> parts = SplitPath(key);
      if (parts.size() < depth) continue;
      std::string name = parts[0];
      for (std::size_t i = 1; i < depth; ++i) name += "." + parts[i];
      names.insert(name);
    }
    return {names.begin(), names.end()};
  }

  bool IsSection(const std::string& path) const {
    for (const std::string& key : known_) {
      if (key.rfind(path + ".", 0) == 0) return true;
    }
    return false;
  }

  YAML::Node Find(const std::string& path) const {
    YAML::Node node;
    node.reset(root_);
    for (const std::string& part : SplitPath(path)) {
      const YAML::Node& current = node;
      if (!current.IsMap() || !current[part]) return YAML::Node(YAML::NodeType::Undefined);
      node.reset(current[part]);
    }
    return node;
  }

  // "FILE:LINE: KEY: problem"; a tree built from the command line has no lines ("--set: KEY: problem").
  void Fail(const std::string& path, const YAML::Node& node, const std::string& problem) {
    const std::string where = node.Mark().is_null() ? file_ : file_ + ":" + std::to_string(node.Mark().line + 1);
    status_ = Status::InvalidArgument(where + ": " + path + ": " + problem);
  }

  template <typename T>
  void Parse(const std::string& path, const YAML::Node& node, T* value) {
    try {
      *value = node.as<T>();
    } catch (const YAML::Exception&) {
      Fail(path, node, std::string("expected ") + TypeName(value) + ", got '" + Scalar(node) + "'");
    }
  }

  void Parse(const std::string& path, const YAML::Node& node, flow::ResponseQuantity* value) {
    if (!flow::ParseResponseQuantity(Scalar(node), value)) {
      Fail(path, node, "expected length or line_parameter, got '" + Scalar(node) + "'");
    }
  }

  void Parse(const std::string& path, const YAML::Node& node, flow::SmoothingMode* value) {
    if (!flow::ParseSmoothingMode(Scalar(node), value)) {
      Fail(path, node, "expected centered or causal, got '" + Scalar(node) + "'");
    }
  }

  void Parse(const std::string& path, const YAML::Node& node, depth::DepthSource* value) {
    if (!depth::ParseDepthSource(Scalar(node), value)) {
      Fail(path, node, "expected auto, images, stereo, flight or none, got '" + Scalar(node) + "'");
    }
  }

  void Parse(const std::string& path, const YAML::Node& node, place::FundamentalMethod* value) {
    if (!place::ParseFundamentalMethod(Scalar(node), value)) {
      Fail(path, node, "expected ransac, usac or magsac, got '" + Scalar(node) + "'");
    }
  }

  static std::string Scalar(const YAML::Node& node) { return node.IsScalar() ? node.Scalar() : "(not a scalar)"; }
  static const char* TypeName(const int*) { return "an integer"; }
  static const char* TypeName(const double*) { return "a number"; }
  static const char* TypeName(const bool*) { return "true or false"; }

  std::string file_;
  YAML::Node root_;
  std::set<std::string> known_;
  Status status_;
};

// Writes each visited field into a YAML tree.
class YamlWriter {
 public:
  template <typename T>
  void Field(const std::string& path, T* value) {
    Slot(path) = *value;
  }
  void Field(const std::string& path, flow::ResponseQuantity* value) { Slot(path) = flow::ToString(*value); }
  void Field(const std::string& path, flow::SmoothingMode* value) { Slot(path) = flow::ToString(*value); }
  void Field(const std::string& path, place::FundamentalMethod* value) { Slot(path) = place::ToString(*value); }
  void Field(const std::string& path, depth::DepthSource* value) { Slot(path) = depth::ToString(*value); }

  YAML::Node root = YAML::Node(YAML::NodeType::Map);

 private:
  YAML::Node Slot(const std::string& path) {
    std::vector<std::string> parts = SplitPath(path);
    YAML::Node node;
    node.reset(root);
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (!node[parts[i]]) node[parts[i]] = YAML::Node(YAML::NodeType::Map);
      node.reset(node[parts[i]]);
    }
    return node[parts.back()];
  }
};

}  // namespace

bool Config::IsValid(std::string* error) const {
  if (!OptionCheck(error).InRange("input.frame_rate_hz", input.frame_rate_hz, 0.0, 10000.0).ok()) return false;
  return flow.IsValid(error) && place.IsValid(error) && change.IsValid(error) && depth.IsValid(error) &&
         map.IsValid(error);
}

Status LoadConfig(const std::string& path, Config* config) {
  YAML::Node root;
  PATROLMAP_RETURN_IF_ERROR(io::LoadYamlFile(path, &root));
  if (root.IsNull()) return Status::Ok();  // an empty file keeps every default
  if (!root.IsMap()) return Status::InvalidArgument(path + ": expected a map of sections at the top level");
  YamlReader reader(path, root);
  VisitConfig(config, &reader);
  reader.CheckUnknown(root, "");
  PATROLMAP_RETURN_IF_ERROR(reader.status());
  std::string error;
  if (!config->IsValid(&error)) return Status::InvalidArgument(path + ": " + error);
  return Status::Ok();
}

::patrolmap::change::ChangeOptions ChangeOptionsOf(const Config& config) {
  ::patrolmap::change::ChangeOptions options = config.change;
  options.route.depth.matching = config.depth.stereo;
  options.route.depth.baselines = config.depth.flight;
  return options;
}

std::string ConfigToYaml(const Config& config) {
  Config copy = config;
  YamlWriter writer;
  VisitConfig(&copy, &writer);
  YAML::Emitter emitter;
  emitter << writer.root;
  return std::string(emitter.c_str()) + "\n";
}

Status ApplySettings(const std::vector<std::string>& settings, Config* config) {
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& setting : settings) {
    const std::size_t equals = setting.find('=');
    const std::vector<std::string> parts = SplitPath(setting.substr(0, equals));
    if (equals == std::string::npos || parts.empty() ||
        std::any_of(parts.begin(), parts.end(), [](const std::string& part) { return part.empty(); }) ||
        setting.back() == '.') {
      return Status::InvalidArgument("--set " + setting + ": expected KEY=VALUE, e.g. place.max_log_nfa=0");
    }
    YAML::Node node;
    node.reset(root);
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (!node[parts[i]] || !node[parts[i]].IsMap()) node[parts[i]] = YAML::Node(YAML::NodeType::Map);
      node.reset(node[parts[i]]);
    }
    node[parts.back()] = setting.substr(equals + 1);
  }
  YamlReader reader("--set", root);
  VisitConfig(config, &reader);
  reader.CheckUnknown(root, "");
  return reader.status();
}

Status LoadCheckedConfig(const std::string& path, const std::vector<std::string>& settings, Config* config) {
  if (!path.empty()) PATROLMAP_RETURN_IF_ERROR(LoadConfig(path, config));
  PATROLMAP_RETURN_IF_ERROR(ApplySettings(settings, config));
  std::string error;
  if (!config->IsValid(&error)) return Status::InvalidArgument(error);
  return Status::Ok();
}

}  // namespace patrolmap::pipeline
