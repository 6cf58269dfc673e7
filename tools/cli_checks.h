// Command-line checks shared by the programs in tools/.
#pragma once

#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace patrolmap::tools {

// A number in [low, high]. Unlike CLI::Range it also refuses NaN and infinity (NaN compares false with
// both bounds, so a range check alone lets it through).
inline CLI::Validator FiniteRange(double low, double high = std::numeric_limits<double>::max()) {
  std::ostringstream range;
  range << "[" << low << ", ";
  if (high == std::numeric_limits<double>::max()) {
    range << "any finite]";
  } else {
    range << high << "]";
  }
  const std::string rule = range.str();
  return CLI::Validator(
      [low, high, rule](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size()) return "not a number: " + text;
        if (!std::isfinite(value) || value < low || value > high) return text + " is not a number in " + rule;
        return "";
      },
      "number in " + rule);
}

// --set KEY=VALUE (repeatable): a configuration key set on the command line, over the --config file.
inline void AddSetOption(CLI::App* app, std::vector<std::string>* settings) {
  app->add_option("--set", *settings,
                  "set a configuration key over the --config file, as KEY=VALUE (e.g. --set place.max_log_nfa=0); "
                  "repeatable; the keys are config/default.yaml's")
      ->type_name("KEY=VALUE")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

}  // namespace patrolmap::tools
