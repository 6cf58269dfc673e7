// Writes ROS messages in either wire format, for the bag tests (bag_messages_test.cc, bag_source_test.cc).
#pragma once

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "bag_messages.h"

namespace patrolmap::io::rosmsg {

// Writes messages as ROS 1 serialises them (packed) or as CDR (aligned after a 4-byte header).
class WireWriter {
 public:
  explicit WireWriter(Wire wire) : wire_(wire) {
    if (wire_ == Wire::kCdr) bytes_ = {0, 1, 0, 0};
  }

  template <typename T>
  WireWriter& Put(T value) {
    if (wire_ == Wire::kCdr) {
      while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0xEE);  // padding is never read
    }
    const auto* raw = reinterpret_cast<const std::uint8_t*>(&value);
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
    return *this;
  }

  WireWriter& String(const std::string& text) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(text.size() + (wire_ == Wire::kCdr ? 1 : 0)));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
    if (wire_ == Wire::kCdr) bytes_.push_back(0);
    return *this;
  }

  WireWriter& Header(std::uint32_t seconds, std::uint32_t nanoseconds, const std::string& frame) {
    if (wire_ == Wire::kRos1) Put<std::uint32_t>(7);  // seq
    Put<std::uint32_t>(seconds).Put<std::uint32_t>(nanoseconds);
    return String(frame);
  }

  WireWriter& Doubles(std::initializer_list<double> values) {
    for (double value : values) Put(value);
    return *this;
  }

  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  Wire wire_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace patrolmap::io::rosmsg
