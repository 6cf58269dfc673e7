// What both map formats share: values written to and read from bytes (the legacy file's sections, the SQLite
// store's blobs), and the checks every loaded value passes, so no crafted map reaches the stages with a value
// the pipeline could not have written.
#pragma once

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "patrolmap/core/key_frame_node.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

inline constexpr int kMaxSiteId = 1 << 30;  // numbering on from a crafted id near INT_MAX would overflow

// Appends values to a byte string in the machine's (little-endian) layout.
class Writer {
 public:
  explicit Writer(std::string* bytes) : bytes_(bytes) {}
  template <typename T>
  void Value(T value) {
    bytes_->append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void String(const std::string& text);
  void Mat(const cv::Mat& mat);
  template <typename T>
  void Vector(const std::vector<T>& values) {
    Value(static_cast<std::uint32_t>(values.size()));
    bytes_->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }

 private:
  std::string* bytes_;
};

// Reads with bounds checks; any overrun sets failed() and yields zeros.
class Reader {
 public:
  Reader(const char* data, std::size_t size) : data_(data), size_(size) {}
  template <typename T>
  T Value() {
    T value{};
    if (!Take(sizeof(T))) return value;
    std::memcpy(&value, data_ + position_ - sizeof(T), sizeof(T));
    return value;
  }
  std::string String();
  cv::Mat Mat();  // 8-bit or float, one channel
  template <typename T>
  std::vector<T> Vector() {
    const std::uint32_t count = Value<std::uint32_t>();
    if (!Take(static_cast<std::size_t>(count) * sizeof(T))) return {};
    std::vector<T> values(count);
    if (count > 0)
      std::memcpy(static_cast<void*>(values.data()), data_ + position_ - count * sizeof(T), count * sizeof(T));
    return values;
  }
  bool failed() const { return failed_; }
  bool done() const { return position_ == size_; }

 private:
  bool Take(std::size_t bytes) {
    if (failed_ || bytes > size_ - position_) return failed_ = true, false;
    position_ += bytes;
    return true;
  }
  const char* data_;
  std::size_t size_;
  std::size_t position_ = 0;
  bool failed_ = false;
};

// A camera pose as stored: time, position, rotation (w, x, y, z).
struct PoseRecord {
  std::int64_t timestamp_ns;
  double position[3];
  double rotation[4];
};
PoseRecord ToRecord(const CameraPoseSample& pose);
CameraPoseSample FromRecord(const PoseRecord& record);
std::vector<PoseRecord> ToRecords(const std::vector<CameraPoseSample>& poses);
std::vector<CameraPoseSample> FromRecords(const std::vector<PoseRecord>& records);

// A node's features: positions, descriptors, bag-of-words words and weights.
void WriteFeatures(const KeyFrameNode& node, Writer* w);
void ReadFeatures(Reader* r, KeyFrameNode* node);

// An object's shape and appearance: its box, points, descriptor, height and label evidence (the rest of a
// MapObject the store keeps in columns).
void WriteObjectShape(const MapObject& object, Writer* w);
void ReadObjectShape(Reader* r, MapObject* object);

Status Corrupt(const std::string& path, const std::string& what);  // "PATH: corrupt map (WHAT)"

bool Finite(std::initializer_list<double> values);
bool ValidFlightId(const std::string& id);
bool ValidNodeValues(const KeyFrameNode& node);  // time, frame, GPS on the globe, finite layout
bool ValidThumbnail(const cv::Mat& thumbnail);   // 8-bit grey, at most 4096 a side
bool ValidFeatures(const KeyFrameNode& node);    // counts agree, finite values, a descriptor kind the map stores
bool ValidEdge(const EdgeData& edge, int a, int b, int nodes);
bool ValidPose(const CameraPoseSample& pose);
bool ValidCameraAndViews(const PatrolRecord& record);
bool ValidObject(const MapObject& object);
bool SortedVoxels(const std::vector<VoxelEvidence>& voxels);
bool ValidGrid(const PatrolRecord& record);  // sorted voxels, a voxel size the options allow, a known depth source
bool ValidRoute(const std::vector<RouteFrame>& route, const CameraIntrinsics& camera);
bool ValidSource(const PatrolRecord& record);
// Every check of a record that needs nothing else: camera, views, objects, grid, route, pose source, log.
Status CheckPatrolRecord(const std::string& path, const PatrolRecord& record);

}  // namespace patrolmap::graph
