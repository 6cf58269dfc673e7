// ROS 1 bags through Debian's rosbag_storage (no ROS master, no catkin workspace): its index gives each
// topic's message times without reading their bytes, and a View streams messages in record-time order a
// chunk at a time, whatever the bag's size.
#include <algorithm>
#include <exception>
#include <map>

#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "bag_file.h"

namespace patrolmap::io {
namespace {

TimestampNs ToNs(const ros::Time& time) { return static_cast<TimestampNs>(time.toNSec()); }

// The message rosbag gives for a damaged bag, in words a user can act on.
Status BagError(const std::string& path, const std::string& topic, const std::exception& error) {
  std::string message = error.what();
  if (message.find("version line") != std::string::npos ||
      message.find("Unsupported bag file version") != std::string::npos) {
    return Status::DataLoss(path + ": not a ROS 1 bag of format 2.0 (rosbag: " + message + ")");
  }
  if (message.find("unindexed") != std::string::npos || message.find("Error reading") != std::string::npos) {
    message += " (the bag is truncated or was not closed; `rosbag reindex` may recover it)";
  }
  return Status::DataLoss(path + (topic.empty() ? "" : ", topic " + topic) + ": " + message);
}

class Ros1Stream : public BagStream {
 public:
  Ros1Stream(const std::string& path, rosbag::Bag* bag, const std::map<std::string, int>& topic_index,
             const std::vector<std::string>& names, std::size_t limit)
      : path_(path), topic_index_(topic_index), limit_(limit), view_(*bag, rosbag::TopicQuery(names)) {
    next_ = view_.begin();
  }

  Status Next(BagMessage* message) override {
    std::string topic;
    try {
      if (next_ == view_.end() || (limit_ > 0 && read_ >= limit_)) return Status::EndOfStream();
      if (read_ > 0) ++next_;
      if (next_ == view_.end()) return Status::EndOfStream();
      const rosbag::MessageInstance& instance = *next_;
      topic = instance.getTopic();
      message->topic = topic_index_.at(topic);
      message->record_ns = ToNs(instance.getTime());
      message->bytes.resize(instance.size());
      ::ros::serialization::OStream stream(message->bytes.data(), static_cast<std::uint32_t>(message->bytes.size()));
      instance.write(stream);
      ++read_;
      return Status::Ok();
    } catch (const std::exception& error) {
      return BagError(path_, topic, error);
    }
  }

 private:
  std::string path_;
  const std::map<std::string, int>& topic_index_;
  std::size_t limit_;
  std::size_t read_ = 0;
  rosbag::View view_;
  rosbag::View::iterator next_;
};

class Ros1Bag : public BagFile {
 public:
  explicit Ros1Bag(std::string path) : path_(std::move(path)) {}

  Status Open() {
    try {
      bag_.open(path_, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      for (const rosbag::ConnectionInfo* connection : all.getConnections()) {
        if (topic_index_.count(connection->topic) > 0) continue;
        topic_index_[connection->topic] = static_cast<int>(topics_.size());
        topics_.push_back({connection->topic, connection->datatype, 0, 0.0});
      }
      for (BagTopic& topic : topics_) {
        rosbag::View view(bag_, rosbag::TopicQuery(topic.name));
        topic.count = view.size();
      }
    } catch (const std::exception& error) {
      return BagError(path_, "", error);
    }
    return Status::Ok();
  }

  rosmsg::Wire wire() const override { return rosmsg::Wire::kRos1; }
  const std::vector<BagTopic>& topics() const override { return topics_; }

  Status Times(int topic, std::vector<TimestampNs>* times) override {
    times->clear();
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(topics_.at(topic).name));
      times->reserve(view.size());
      for (const rosbag::MessageInstance& instance : view) times->push_back(ToNs(instance.getTime()));
    } catch (const std::exception& error) {
      return BagError(path_, topics_.at(topic).name, error);
    }
    return Status::Ok();
  }

  Status Stream(const std::vector<int>& topics, std::size_t limit, std::unique_ptr<BagStream>* stream) override {
    std::vector<std::string> names;
    for (int topic : topics) names.push_back(topics_.at(topic).name);
    try {
      *stream = std::make_unique<Ros1Stream>(path_, &bag_, topic_index_, names, limit);
    } catch (const std::exception& error) {
      return BagError(path_, "", error);
    }
    return Status::Ok();
  }

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::vector<BagTopic> topics_;
  std::map<std::string, int> topic_index_;
};

}  // namespace

bool Ros1BagsSupported() { return true; }

Status OpenRos1Bag(const std::string& path, std::unique_ptr<BagFile>* bag) {
  auto ros1 = std::make_unique<Ros1Bag>(path);
  PATROLMAP_RETURN_IF_ERROR(ros1->Open());
  *bag = std::move(ros1);
  return Status::Ok();
}

}  // namespace patrolmap::io
