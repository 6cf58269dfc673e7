// Internal: a ROS bag as topics and a time-ordered stream of their messages' bytes, whatever its version.
// ROS 1 bags are read with Debian's rosbag_storage, ROS 2 bags (sqlite3 storage) with libsqlite3; the
// messages are decoded by bag_messages.h and turned into frames by the bag FrameSource (bag_source.cc).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bag_messages.h"
#include "patrolmap/core/status.h"
#include "patrolmap/io/bag.h"

namespace patrolmap::io {

struct BagMessage {
  int topic = -1;             // index into BagFile::topics()
  TimestampNs record_ns = 0;  // when the recorder received it
  std::vector<std::uint8_t> bytes;
};

class BagStream {
 public:
  virtual ~BagStream() = default;
  // The next message in record-time order; Status::EndOfStream() after the last. A damaged part of the
  // bag fails with a message naming the file and, where known, the topic.
  virtual Status Next(BagMessage* message) = 0;
};

class BagFile {
 public:
  virtual ~BagFile() = default;
  virtual rosmsg::Wire wire() const = 0;
  // Every topic of the bag with its type and message count (rate_hz 0 until Times is read).
  virtual const std::vector<BagTopic>& topics() const = 0;
  // The record times of one topic's messages, ascending, without reading their bytes where the format
  // allows (ROS 1's index).
  virtual Status Times(int topic, std::vector<TimestampNs>* times) = 0;
  // A stream over the messages of `topics`, at most `limit` of them (0: all).
  virtual Status Stream(const std::vector<int>& topics, std::size_t limit, std::unique_ptr<BagStream>* stream) = 0;
};

// Each names the file and the problem when the bag cannot be read (missing, truncated, not a bag, an
// unknown compression or storage), or when the library it needs was left out of the build.
Status OpenRos1Bag(const std::string& path, std::unique_ptr<BagFile>* bag);
Status OpenRos2Bag(const std::string& folder, std::unique_ptr<BagFile>* bag);

}  // namespace patrolmap::io
