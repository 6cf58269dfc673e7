#include "patrolmap/core/option_check.h"

#include <cmath>
#include <sstream>

namespace patrolmap {
namespace {

std::string Format(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

OptionCheck& OptionCheck::Fail(const char* key, const std::string& value, const std::string& rule) {
  if (ok_ && error_ != nullptr) *error_ = std::string(key) + " = " + value + ": " + rule;
  ok_ = false;
  return *this;
}

OptionCheck& OptionCheck::InRange(const char* key, double value, double low, double high) {
  if (!ok_ || (std::isfinite(value) && value >= low && value <= high)) return *this;
  return Fail(key, Format(value), "must be a number in [" + Format(low) + ", " + Format(high) + "]");
}

OptionCheck& OptionCheck::AboveAtMost(const char* key, double value, double low, double high) {
  if (!ok_ || (std::isfinite(value) && value > low && value <= high)) return *this;
  return Fail(key, Format(value), "must be a number in (" + Format(low) + ", " + Format(high) + "]");
}

OptionCheck& OptionCheck::InRange(const char* key, int value, int low, int high) {
  if (!ok_ || (value >= low && value <= high)) return *this;
  return Fail(key, std::to_string(value),
              "must be an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
}

OptionCheck& OptionCheck::Holds(const char* key, double value, bool holds, const char* rule) {
  if (!ok_ || (holds && std::isfinite(value))) return *this;
  return Fail(key, Format(value), rule);
}

}  // namespace patrolmap
