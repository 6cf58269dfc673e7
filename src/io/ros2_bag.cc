// ROS 2 bags with sqlite3 storage: a folder with metadata.yaml (the list of .db3 files, in order) and the
// files, each with the tables topics(id, name, type, serialization_format) and messages(id, topic_id,
// timestamp, data). Messages are stepped through with one query per file, ordered by timestamp, so a
// bag of any size is read a message at a time.
#include <algorithm>
#include <filesystem>
#include <map>

#include "bag_file.h"
#include "image_times.h"
#include "patrolmap/core/sqlite.h"
#include "patrolmap/io/yaml_file.h"

namespace fs = std::filesystem;

namespace patrolmap::io {
namespace {

Status OpenDatabase(const std::string& path, SqliteDatabase* database) {
  if (!fs::is_regular_file(path)) return Status::NotFound(path + ": no such file (listed in metadata.yaml)");
  return SqliteDatabase::Open(path, SqliteDatabase::Mode::kReadOnly, database);
}

// One .db3 file: its topic ids mapped to the bag's topic indices.
struct BagDatabase {
  std::string path;
  SqliteDatabase database;
  std::map<int, int> topic_of_id;  // topics.id -> index into the bag's topics
};

class Ros2Stream : public BagStream {
 public:
  Ros2Stream(std::vector<BagDatabase>* files, std::vector<int> topics, std::size_t limit)
      : files_(files), topics_(std::move(topics)), limit_(limit) {}

  Status Next(BagMessage* message) override {
    while (limit_ == 0 || read_ < limit_) {
      if (!statement_) {
        if (next_file_ >= files_->size()) return Status::EndOfStream();
        PATROLMAP_RETURN_IF_ERROR(StartFile((*files_)[next_file_++]));
      }
      const BagDatabase& file = (*files_)[next_file_ - 1];
      Status status;
      if (!statement_->Step(&status)) {
        PATROLMAP_RETURN_IF_ERROR(status);
        statement_.reset();
        continue;
      }
      const auto topic = file.topic_of_id.find(static_cast<int>(statement_->Int(0)));
      if (topic == file.topic_of_id.end()) continue;
      message->topic = topic->second;
      message->record_ns = statement_->Int(1);
      std::size_t size = 0;
      const unsigned char* data = statement_->Blob(2, &size);
      if (data == nullptr) size = 0;
      message->bytes.assign(data, data + size);
      ++read_;
      return Status::Ok();
    }
    return Status::EndOfStream();
  }

 private:
  Status StartFile(BagDatabase& file) {
    std::string ids;
    for (const auto& [id, index] : file.topic_of_id) {
      if (std::find(topics_.begin(), topics_.end(), index) == topics_.end()) continue;
      ids += (ids.empty() ? "" : ",") + std::to_string(id);
    }
    if (ids.empty()) ids = "-1";
    statement_ = std::make_unique<SqliteStatement>();
    return file.database.Prepare(
        "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + ids + ") ORDER BY timestamp, id",
        statement_.get(), "reading messages");
  }

  std::vector<BagDatabase>* files_;
  std::vector<int> topics_;
  std::size_t limit_;
  std::size_t read_ = 0;
  std::size_t next_file_ = 0;
  std::unique_ptr<SqliteStatement> statement_;
};

class Ros2Bag : public BagFile {
 public:
  explicit Ros2Bag(std::string folder) : folder_(std::move(folder)) {}

  Status Open() {
    std::vector<std::string> names;
    PATROLMAP_RETURN_IF_ERROR(ReadMetadata(&names));
    for (const std::string& name : names) {
      BagDatabase file;
      file.path = folder_ + "/" + name;
      PATROLMAP_RETURN_IF_ERROR(OpenDatabase(file.path, &file.database));
      PATROLMAP_RETURN_IF_ERROR(ReadTopics(&file));
      files_.push_back(std::move(file));
    }
    return CountMessages();
  }

  rosmsg::Wire wire() const override { return rosmsg::Wire::kCdr; }
  const std::vector<BagTopic>& topics() const override { return topics_; }

  Status Times(int topic, std::vector<TimestampNs>* times) override {
    times->clear();
    for (BagDatabase& file : files_) {
      for (const auto& [id, index] : file.topic_of_id) {
        if (index != topic) continue;
        SqliteStatement statement;
        PATROLMAP_RETURN_IF_ERROR(file.database.Prepare(
            "SELECT timestamp FROM messages WHERE topic_id = " + std::to_string(id) + " ORDER BY timestamp", &statement,
            "reading message times"));
        Status status;
        while (statement.Step(&status)) times->push_back(statement.Int(0));
        PATROLMAP_RETURN_IF_ERROR(status);
      }
    }
    return Status::Ok();
  }

  Status Stream(const std::vector<int>& topics, std::size_t limit, std::unique_ptr<BagStream>* stream) override {
    *stream = std::make_unique<Ros2Stream>(&files_, topics, limit);
    return Status::Ok();
  }

 private:
  Status ReadMetadata(std::vector<std::string>* names) {
    const std::string path = folder_ + "/metadata.yaml";
    YAML::Node root;
    PATROLMAP_RETURN_IF_ERROR(LoadYamlMap(path, &root));
    const YAML::Node info = root["rosbag2_bagfile_information"];
    if (!info || !info.IsMap()) return Status::DataLoss(path + ": no 'rosbag2_bagfile_information' map");
    const std::string storage =
        info["storage_identifier"] && info["storage_identifier"].IsScalar() ? info["storage_identifier"].Scalar() : "";
    if (storage != "sqlite3") {
      return Status::InvalidArgument(path + ": storage_identifier '" + storage +
                                     "' is not sqlite3, the only ROS 2 storage read (`ros2 bag convert` "
                                     "writes sqlite3)");
    }
    // rosbag2 compresses whole files (.db3.zstd) or each message's bytes; neither is read.
    const YAML::Node compression = info["compression_format"];
    const std::string format = compression && compression.IsScalar() ? compression.Scalar() : "";
    if (!format.empty()) {
      return Status::InvalidArgument(path + ": compression_format '" + format +
                                     "': compressed ROS 2 bags are not read (`ros2 bag decompress` or `ros2 bag "
                                     "convert` without compression writes a plain one)");
    }
    const YAML::Node files = info["relative_file_paths"];
    if (!files || !files.IsSequence() || files.size() == 0) {
      return Status::DataLoss(path + ": 'relative_file_paths' must list the bag's .db3 files");
    }
    for (const YAML::Node& file : files) {
      const std::string name = file.IsScalar() ? file.Scalar() : "";
      if (name.empty() || name.find("..") != std::string::npos || name.front() == '/') {
        return Status::DataLoss(path + ": relative_file_paths holds '" + name + "', not a file inside the bag");
      }
      names->push_back(name);
    }
    return Status::Ok();
  }

  Status ReadTopics(BagDatabase* file) {
    SqliteStatement statement;
    PATROLMAP_RETURN_IF_ERROR(file->database.Prepare("SELECT id, name, type, serialization_format FROM topics",
                                                     &statement, "not a ROS 2 bag database"));
    Status status;
    while (statement.Step(&status)) {
      const std::string name = statement.Text(1);
      const std::string format = statement.Text(3);
      if (format != "cdr") {
        return Status::InvalidArgument(file->path + ", topic " + name + ": serialization format '" + format +
                                       "' is not cdr, the only one read");
      }
      auto known = std::find_if(topics_.begin(), topics_.end(), [&](const BagTopic& t) { return t.name == name; });
      if (known == topics_.end()) known = topics_.insert(topics_.end(), {name, statement.Text(2), 0, 0.0});
      file->topic_of_id[static_cast<int>(statement.Int(0))] = static_cast<int>(known - topics_.begin());
    }
    return status;
  }

  Status CountMessages() {
    for (BagDatabase& file : files_) {
      SqliteStatement statement;
      PATROLMAP_RETURN_IF_ERROR(file.database.Prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id",
                                                      &statement, "counting messages"));
      Status status;
      while (statement.Step(&status)) {
        const auto topic = file.topic_of_id.find(static_cast<int>(statement.Int(0)));
        if (topic != file.topic_of_id.end()) topics_[topic->second].count += statement.Int(1);
      }
      PATROLMAP_RETURN_IF_ERROR(status);
    }
    return Status::Ok();
  }

  std::string folder_;
  std::vector<BagDatabase> files_;
  std::vector<BagTopic> topics_;
};

}  // namespace

bool Ros2BagsSupported() { return true; }

Status OpenRos2Bag(const std::string& folder, std::unique_ptr<BagFile>* bag) {
  auto ros2 = std::make_unique<Ros2Bag>(folder);
  PATROLMAP_RETURN_IF_ERROR(ros2->Open());
  *bag = std::move(ros2);
  return Status::Ok();
}

}  // namespace patrolmap::io
