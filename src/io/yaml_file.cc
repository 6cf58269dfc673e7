#include "patrolmap/io/yaml_file.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

namespace patrolmap::io {
namespace {

// Deepest nesting of maps and lists a patrolmap file may have (its own files use 3).
constexpr int kMaxYamlDepth = 32;

// Reads a YAML stream's events before it is built into a tree, and notes the first thing patrolmap's files never
// hold but a hostile one could: an alias (a self-alias builds a cyclic tree, ten aliases of ten a tree of 10^10
// nodes), nesting deeper than kMaxYamlDepth, or a second document (which a tree would drop unseen).
class ShapeCheck : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override {
    if (++documents_ > 1) Note(mark, "a second YAML document in one file (patrolmap reads one)");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    Note(mark, "a YAML alias (*name); patrolmap's files hold no aliases, write the value out");
  }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnMapEnd() override { --depth_; }

  const std::string& problem() const { return problem_; }
  int line() const { return line_; }

 private:
  void Open(const YAML::Mark& mark) {
    if (++depth_ > kMaxYamlDepth) Note(mark, "maps and lists nested deeper than " + std::to_string(kMaxYamlDepth));
  }
  void Note(const YAML::Mark& mark, std::string problem) {
    if (!problem_.empty()) return;
    problem_ = std::move(problem);
    line_ = mark.line + 1;
  }

  int documents_ = 0, depth_ = 0, line_ = 0;
  std::string problem_;
};

// The first problem of ShapeCheck in `text`, or "" (a syntax error is left to YAML::Load, which names it).
std::string CheckShape(const std::string& text, int* line) {
  std::istringstream stream(text);
  ShapeCheck check;
  try {
    YAML::Parser parser(stream);
    while (check.problem().empty() && parser.HandleNextDocument(check)) {
    }
  } catch (const YAML::Exception&) {
    if (check.problem().empty()) return "";
  }
  *line = check.line();
  return check.problem();
}

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
  std::error_code ignored;  // a path that cannot be looked at is reported as missing
  const std::filesystem::file_status status = std::filesystem::status(path, ignored);
  if (!std::filesystem::exists(status)) return Status::NotFound(path + ": no such file");
  if (!std::filesystem::is_regular_file(status)) {
    return Status::InvalidArgument(path + ": not a regular file (a folder, device or pipe)");
  }
  std::ifstream stream(path);
  if (!stream) return Status::IoError(path + ": cannot open for reading");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  std::string text = buffer.str();
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';  // keep line numbers intact
  int line = 0;
  const std::string shape = CheckShape(text, &line);
  if (!shape.empty()) return Status::DataLoss(path + ":" + std::to_string(line) + ": " + shape);
  try {
    *root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    return Status::DataLoss(path + ":" + std::to_string(error.mark.line + 1) + ": " + error.msg);
  } catch (const std::exception& error) {  // yaml-cpp throws others too (its depth guard, allocation)
    return Status::DataLoss(path + ": not a YAML file patrolmap can read (" + error.what() + ")");
  }
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
