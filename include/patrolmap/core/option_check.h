// The one helper every options struct's IsValid() is built from (Ceres's
// Solver::Options::IsValid is the model): each rule names the key, the value
// and the range it must lie in, and the first rule that fails writes
//   "flow.voting.max_votes = 300: must be an integer in [3, 100]"
// into the error. Floating-point values must also be finite, so NaN and inf
// are refused by every rule.
#pragma once

#include <string>

namespace patrolmap {

class OptionCheck {
 public:
  // `error` (may be null) receives the first failure's message.
  explicit OptionCheck(std::string* error) : error_(error) {}

  // low <= value <= high.
  OptionCheck& InRange(const char* key, double value, double low, double high);
  // low < value <= high.
  OptionCheck& AboveAtMost(const char* key, double value, double low, double high);
  // An integer in [low, high].
  OptionCheck& InRange(const char* key, int value, int low, int high);
  // A rule of its own: fails with "key = value: rule" when `holds` is false.
  OptionCheck& Holds(const char* key, double value, bool holds, const char* rule);

  bool ok() const { return ok_; }

 private:
  OptionCheck& Fail(const char* key, const std::string& value, const std::string& rule);

  std::string* error_;
  bool ok_ = true;
};

}  // namespace patrolmap
