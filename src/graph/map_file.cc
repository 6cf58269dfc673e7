#include "patrolmap/graph/map_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/flight_id.h"
#include "patrolmap/core/image_header.h"
#include "patrolmap/vocab/descriptors.h"

#include <opencv2/core.hpp>

namespace patrolmap::graph {
namespace {

constexpr char kMagic[8] = {'P', 'M', 'M', 'A', 'P', '\0', '\0', '\0'};
// 2: PTRL section (patrol records); 3: VOCB section (vocabulary); 4: voxels the grid's memory budget dropped;
// 5: the patrol's depth source; 6: the frames kept along the route; 7: whether the patrol's log was timed;
// 8: features keep their positions only (no size, angle, response, octave), descriptors may be packed 4-bit;
// 9: where the patrol's camera poses came from; 10: the patrol's lens distortion; 11: the patrol's log and its digest;
// 12: each object's site id
constexpr std::uint32_t kVersion = 12;
constexpr std::size_t kMaxRouteJpegBytes = 16u << 20;
constexpr int kMaxRouteFrameSide = 2048;  // change.route_frames.max_width's largest value
constexpr std::uint32_t kOldestVersion = 1;
constexpr int kMaxSiteId = 1 << 30;  // numbering on from a crafted id near INT_MAX would overflow

// Where a section's bytes go: counted (its length), checksummed, or written to the file. A section is built
// once for each, so saving never holds a section in memory: the features of an hour's map are 45 MB.
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void Append(const char* data, std::size_t size) = 0;
};

class Writer {
 public:
  explicit Writer(Sink* sink) : sink_(sink) {}
  template <typename T>
  void Value(T value) {
    sink_->Append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void String(const std::string& text) {
    Value(static_cast<std::uint32_t>(text.size()));
    sink_->Append(text.data(), text.size());
  }
  void Mat(const cv::Mat& mat) {
    const cv::Mat continuous = mat.isContinuous() ? mat : mat.clone();
    Value(static_cast<std::int32_t>(mat.type()));
    Value(static_cast<std::int32_t>(mat.rows));
    Value(static_cast<std::int32_t>(mat.cols));
    sink_->Append(reinterpret_cast<const char*>(continuous.data), continuous.total() * continuous.elemSize());
  }
  template <typename T>
  void Vector(const std::vector<T>& values) {
    Value(static_cast<std::uint32_t>(values.size()));
    sink_->Append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }

 private:
  Sink* sink_;
};

class CountingSink : public Sink {
 public:
  void Append(const char*, std::size_t size) override { size_ += size; }
  std::uint64_t size() const { return size_; }

 private:
  std::uint64_t size_ = 0;
};

class ChecksumSink : public Sink {
 public:
  explicit ChecksumSink(std::uint64_t size) : stream_(size) {}
  void Append(const char* data, std::size_t size) override { stream_.Add(data, size); }
  std::uint64_t checksum() const { return stream_.Finish(); }

 private:
  ChecksumStream stream_;
};

// Writes to the file in pieces of about kPiece bytes; keeps the first failure.
class FileSink : public Sink {
 public:
  explicit FileSink(AtomicFile* file) : file_(file) {}
  void Append(const char* data, std::size_t size) override {
    buffer_.append(data, size);
    if (buffer_.size() >= kPiece) Flush();
  }
  Status Finish() {
    Flush();
    return status_;
  }

 private:
  static constexpr std::size_t kPiece = 1 << 20;
  void Flush() {
    if (status_.ok() && !buffer_.empty()) status_ = file_->Write(buffer_);
    buffer_.clear();
  }
  AtomicFile* file_;
  std::string buffer_;
  Status status_;
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
  std::string String() {
    const std::uint32_t length = Value<std::uint32_t>();
    if (!Take(length)) return {};
    return std::string(data_ + position_ - length, length);
  }
  cv::Mat Mat() {
    const int type = Value<std::int32_t>(), rows = Value<std::int32_t>(), cols = Value<std::int32_t>();
    if (failed_ || rows < 0 || cols < 0 || (type != CV_8UC1 && type != CV_32FC1)) return Fail(), cv::Mat();
    // The bytes must be in the file before anything is allocated (a header may claim 2^31 x 2^31).
    const std::size_t bytes =
        static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) * (type == CV_8UC1 ? 1 : 4);
    if (bytes > size_ - position_) return Fail(), cv::Mat();
    cv::Mat mat(rows, cols, type);
    if (!Take(bytes)) return cv::Mat();
    if (bytes > 0) std::memcpy(mat.data, data_ + position_ - bytes, bytes);
    return mat;
  }
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
  void Fail() { failed_ = true; }
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

// A feature as map format 7 and older kept it; only the position is read.
struct KeyPointRecord {
  float x, y, size, angle, response;
  std::int32_t octave;
};

void NodeSection(const TopoMap& map, Writer* out) {
  Writer& w = *out;
  w.Value(static_cast<std::uint32_t>(map.node_count()));
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    w.String(n.flight);
    w.Value(n.timestamp_ns);
    w.Value(n.frame_index);
    w.Mat(n.thumbnail);
    w.Value(static_cast<std::uint8_t>(n.gps.has_value()));
    const Eigen::Vector2d gps = n.gps.value_or(Eigen::Vector2d::Zero());
    for (double v : {gps.x(), gps.y(), n.layout.x(), n.layout.y(), n.heading}) w.Value(v);
  }
}

void EdgeSection(const TopoMap& map, Writer* out) {
  Writer& w = *out;
  const std::vector<TopoMap::Edge> edges = map.Edges();
  w.Value(static_cast<std::uint32_t>(edges.size()));
  for (const TopoMap::Edge& e : edges) {
    w.Value(static_cast<std::uint32_t>(e.a));
    w.Value(static_cast<std::uint32_t>(e.b));
    w.Value(static_cast<std::uint8_t>(e.data.kind));
    w.Value(e.data.bow_score);
    w.Value(e.data.matched_fraction);
    w.Value(static_cast<std::int32_t>(e.data.inliers));
    w.Value(e.data.log_nfa);
  }
}

void FeatureSection(const TopoMap& map, Writer* out) {
  Writer& w = *out;
  w.Value(static_cast<std::uint32_t>(map.node_count()));
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    w.Vector(n.points);
    w.Mat(n.descriptors);
    w.Vector(n.bow.words);
    w.Vector(n.bow.weights);
  }
}

struct PoseRecord {
  std::int64_t timestamp_ns;
  double position[3];
  double rotation[4];  // w, x, y, z
};

void WriteObject(const MapObject& o, Writer* w) {
  w->Value<std::int32_t>(o.id);
  w->String(o.label);
  w->Value(o.confidence);
  w->Value<std::int32_t>(o.detections);
  w->Value<std::uint8_t>(o.confirmed ? 1 : 0);
  for (const Eigen::Vector3d* v : {&o.centroid, &o.box_min, &o.box_max}) {
    for (int k = 0; k < 3; ++k) w->Value((*v)[k]);
  }
  w->Vector(o.points);
  w->Vector(o.descriptor);
  w->Value(o.height);
  w->Value(static_cast<std::uint32_t>(o.labels.size()));
  for (const MapObject::LabelEvidence& e : o.labels) {
    w->String(e.label);
    w->Value(e.confidence_sum);
    w->Value<std::int32_t>(e.count);
  }
  w->Value(o.first_seen_ns);
  w->Value(o.last_seen_ns);
}

PoseRecord ToRecord(const CameraPoseSample& v) {
  return {v.timestamp_ns,
          {v.position.x(), v.position.y(), v.position.z()},
          {v.rotation.w(), v.rotation.x(), v.rotation.y(), v.rotation.z()}};
}

CameraPoseSample FromRecord(const PoseRecord& v) {
  return {v.timestamp_ns, Eigen::Vector3d(v.position[0], v.position[1], v.position[2]),
          Eigen::Quaterniond(v.rotation[0], v.rotation[1], v.rotation[2], v.rotation[3])};
}

// Per frame: time, frame index, flags (1: pose, 2: GPS), the pose, latitude and longitude, the JPEG bytes.
void WriteRoute(const std::vector<RouteFrame>& route, Writer* w) {
  w->Value(static_cast<std::uint32_t>(route.size()));
  for (const RouteFrame& f : route) {
    w->Value(f.timestamp_ns);
    w->Value(f.frame_index);
    w->Value<std::uint8_t>((f.pose ? 1 : 0) | (f.gps ? 2 : 0));
    w->Value(ToRecord(f.pose.value_or(CameraPoseSample())));
    const Eigen::Vector2d gps = f.gps.value_or(Eigen::Vector2d::Zero());
    w->Value(gps.x());
    w->Value(gps.y());
    w->Vector(f.jpeg);
  }
}

void PatrolSection(const TopoMap& map, Writer* out) {
  Writer& w = *out;
  w.Value(static_cast<std::uint32_t>(map.patrols().size()));
  for (const PatrolRecord& p : map.patrols()) {
    w.String(p.flight);
    for (double v : {p.camera.fx, p.camera.fy, p.camera.cx, p.camera.cy}) w.Value(v);
    w.Value<std::int32_t>(p.camera.width);
    w.Value<std::int32_t>(p.camera.height);
    w.Value<std::int32_t>(p.feature_image_width);
    std::vector<PoseRecord> views;
    for (const CameraPoseSample& v : p.views) views.push_back(ToRecord(v));
    w.Vector(views);
    w.Value<std::uint8_t>(p.has_objects ? 1 : 0);
    w.Value(static_cast<std::uint32_t>(p.objects.size()));
    for (const MapObject& o : p.objects) WriteObject(o, &w);
    w.Value(p.grid.voxel_size);
    w.Vector(p.grid.voxels);
    w.Value<std::int64_t>(p.grid.evicted_voxels);
    w.String(p.depth_source);
    WriteRoute(p.route, &w);
    w.Value<std::uint8_t>(p.timed ? 1 : 0);
    w.String(p.pose_source);
    for (double k : p.distortion) w.Value(k);
    w.String(p.source);
    w.String(p.source_digest);
    std::vector<std::int32_t> site_ids;
    for (const MapObject& o : p.objects) site_ids.push_back(o.site_id);
    w.Vector(site_ids);
  }
}

void VocabularySection(const TopoMap& map, Writer* out) {
  Writer& w = *out;
  w.Value(map.vocabulary().fingerprint);
  w.String(map.vocabulary().name);
}

// Writes one section (tag, length, checksum, payload), built three times: counted, checksummed, written.
Status WriteSection(const char (&tag)[5], const TopoMap& map, void (*build)(const TopoMap&, Writer*),
                    AtomicFile* file) {
  CountingSink length;
  Writer counting(&length);
  build(map, &counting);
  ChecksumSink checksum(length.size());
  Writer checksumming(&checksum);
  build(map, &checksumming);
  std::string header(tag, 4);
  const std::uint64_t size = length.size(), sum = checksum.checksum();
  header.append(reinterpret_cast<const char*>(&size), 8);
  header.append(reinterpret_cast<const char*>(&sum), 8);
  PATROLMAP_RETURN_IF_ERROR(file->Write(header));
  FileSink out(file);
  Writer writing(&out);
  build(map, &writing);
  return out.Finish();
}

Status Corrupt(const std::string& path, const std::string& what) {
  return Status::DataLoss(path + ": corrupt map (" + what + ")");
}

// Flight ids as readers keep them (core/flight_id.h); maps written before ids were cut at 200 bytes hold longer ones.
bool ValidFlightId(const std::string& id) { return IsValidFlightId(id, 1000); }

// A patrol's log as the pipeline records it: printable text, and a digest of 16 hex digits (or none).
bool ValidSource(const PatrolRecord& p) {
  const std::string& d = p.source_digest;
  return p.source.size() <= 4096 && PrintableText(p.source) == p.source &&
         (d.empty() || (d.size() == 16 && std::all_of(d.begin(), d.end(), [](char c) {
                          return std::isxdigit(static_cast<unsigned char>(c)) != 0;
                        })));
}

bool Finite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// Node values a reader could have written: a valid time, a frame index from 0, GPS on the globe, a
// finite layout and heading.
bool ValidNodeValues(const KeyFrameNode& n) {
  const bool gps_ok = !n.gps || (std::abs((*n.gps)[0]) <= 90.0 && std::abs((*n.gps)[1]) <= 180.0);
  return ValidTimestamp(n.timestamp_ns) && n.frame_index >= 0 && gps_ok &&
         Finite({n.layout.x(), n.layout.y(), n.heading});
}

Status ParseNodes(const std::string& path, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    KeyFrameNode n;
    n.flight = r->String();
    n.timestamp_ns = r->Value<TimestampNs>();
    n.frame_index = r->Value<std::int64_t>();
    n.thumbnail = r->Mat();
    const bool has_gps = r->Value<std::uint8_t>() != 0;
    double v[5];
    for (double& value : v) value = r->Value<double>();
    if (has_gps) n.gps = Eigen::Vector2d(v[0], v[1]);
    n.layout = Eigen::Vector2d(v[2], v[3]);
    n.heading = v[4];
    if (!ValidFlightId(n.flight)) return Corrupt(path, "flight id of node " + std::to_string(i));
    if (!r->failed() && !ValidNodeValues(n))
      return Corrupt(path, "time, frame, GPS or layout of node " + std::to_string(i));
    if (!r->failed() &&
        (n.thumbnail.empty() || n.thumbnail.type() != CV_8UC1 || n.thumbnail.cols > 4096 || n.thumbnail.rows > 4096)) {
      return Corrupt(path, "thumbnail of node " + std::to_string(i));
    }
    map->AddNode(std::move(n));
  }
  return r->failed() || !r->done() ? Corrupt(path, "node section") : Status::Ok();
}

Status ParseEdges(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  std::set<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>> seen;
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    const auto a = r->Value<std::uint32_t>(), b = r->Value<std::uint32_t>();
    EdgeData e;
    const auto kind = r->Value<std::uint8_t>();
    e.bow_score = r->Value<double>();
    e.matched_fraction = r->Value<double>();
    e.inliers = r->Value<std::int32_t>();
    if (version >= 3) e.log_nfa = r->Value<double>();
    if (r->failed()) break;
    if (kind > 1 || a >= static_cast<std::uint32_t>(map->node_count()) ||
        b >= static_cast<std::uint32_t>(map->node_count()) || a == b ||
        !Finite({e.bow_score, e.matched_fraction, e.log_nfa}) || e.bow_score < 0.0 || e.matched_fraction < 0.0 ||
        e.inliers < 0) {
      return Corrupt(path, "edge " + std::to_string(i));
    }
    // A map holds one edge of a kind between two nodes (a crafted one could repeat it thousands of times).
    if (!seen.insert({std::min(a, b), std::max(a, b), kind}).second) {
      return Corrupt(path, "edge " + std::to_string(i) + " repeats another");
    }
    e.kind = static_cast<EdgeKind>(kind);
    map->AddEdge(static_cast<int>(a), static_cast<int>(b), e);
  }
  return r->failed() || !r->done() ? Corrupt(path, "edge section") : Status::Ok();
}

Status ParseFeatures(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  if (r->Value<std::uint32_t>() != static_cast<std::uint32_t>(map->node_count())) return Corrupt(path, "feature count");
  for (int i = 0; i < map->node_count() && !r->failed(); ++i) {
    KeyFrameNode& n = map->mutable_node(i);
    if (version >= 8) {
      n.points = r->Vector<cv::Point2f>();
    } else {
      for (const KeyPointRecord& k : r->Vector<KeyPointRecord>()) n.points.emplace_back(k.x, k.y);
    }
    n.descriptors = r->Mat();
    n.bow.words = r->Vector<vocab::WordId>();
    n.bow.weights = r->Vector<float>();
    if (n.bow.words.size() != n.bow.weights.size() ||
        (!n.descriptors.empty() && static_cast<std::size_t>(n.descriptors.rows) != n.points.size()) ||
        !vocab::IsStoredDescriptorKind(n.descriptors) ||
        !std::all_of(n.points.begin(), n.points.end(), [](const cv::Point2f& p) { return std::isfinite(p.x + p.y); }) ||
        (n.descriptors.depth() == CV_32F && !cv::checkRange(n.descriptors)) ||
        !std::all_of(n.bow.weights.begin(), n.bow.weights.end(), [](float w) { return std::isfinite(w) && w >= 0; })) {
      return Corrupt(path, "features of node " + std::to_string(i));
    }
  }
  return r->failed() || !r->done() ? Corrupt(path, "feature section") : Status::Ok();
}

MapObject ReadObject(Reader* r) {
  MapObject o;
  o.id = r->Value<std::int32_t>();
  o.label = r->String();
  o.confidence = r->Value<double>();
  o.detections = r->Value<std::int32_t>();
  o.confirmed = r->Value<std::uint8_t>() != 0;
  for (Eigen::Vector3d* v : {&o.centroid, &o.box_min, &o.box_max}) {
    for (int k = 0; k < 3; ++k) (*v)[k] = r->Value<double>();
  }
  o.points = r->Vector<Eigen::Vector3f>();
  o.descriptor = r->Vector<float>();
  o.height = r->Value<double>();
  const std::uint32_t labels = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < labels && !r->failed(); ++i) {
    MapObject::LabelEvidence e;
    e.label = r->String();
    e.confidence_sum = r->Value<double>();
    e.count = r->Value<std::int32_t>();
    o.labels.push_back(e);
  }
  o.first_seen_ns = r->Value<TimestampNs>();
  o.last_seen_ns = r->Value<TimestampNs>();
  return o;
}

// Sorted voxels, each well inside the integer range, so the grid's neighbour and shift arithmetic cannot overflow
// (2^30 voxels of 1 cm are 10,000 km).
bool SortedVoxels(const std::vector<VoxelEvidence>& voxels) {
  constexpr int kMaxIndex = 1 << 30;
  const auto inside = [](const VoxelEvidence& v) {
    return std::max({v.x, v.y, v.z}) <= kMaxIndex && std::min({v.x, v.y, v.z}) >= -kMaxIndex;
  };
  return std::is_sorted(voxels.begin(), voxels.end(), VoxelBefore) && std::all_of(voxels.begin(), voxels.end(), inside);
}

// A pose with a valid time, a finite position and a rotation of about unit norm.
bool ValidPose(const CameraPoseSample& v) {
  const double norm = v.rotation.coeffs().norm();
  return ValidTimestamp(v.timestamp_ns) && v.position.allFinite() && std::isfinite(norm) && norm > 0.5 && norm < 2.0;
}

// A patrol's camera as the pipeline records it (valid, or all zero for a log without one), its lens distortion
// (finite and bounded), and valid views.
bool ValidCameraAndViews(const PatrolRecord& p) {
  const CameraIntrinsics& c = p.camera;
  constexpr int kMaxImageSide = 100000;
  const bool unknown = c.fx == 0.0 && c.fy == 0.0 && c.cx == 0.0 && c.cy == 0.0 && c.width == 0 && c.height == 0;
  const bool camera_ok = unknown || (Finite({c.fx, c.fy, c.cx, c.cy}) && c.valid() && c.width <= kMaxImageSide &&
                                     c.height <= kMaxImageSide);
  if (!camera_ok || p.feature_image_width < 0 || p.feature_image_width > kMaxImageSide) return false;
  if (!PlausibleDistortion(p.distortion)) return false;
  return std::all_of(p.views.begin(), p.views.end(), ValidPose);
}

bool ValidObject(const MapObject& o) {
  const auto finite_points =
      std::all_of(o.points.begin(), o.points.end(), [](const Eigen::Vector3f& x) { return x.allFinite(); });
  const auto finite_descriptor =
      std::all_of(o.descriptor.begin(), o.descriptor.end(), [](float x) { return std::isfinite(x); });
  const auto finite_labels = std::all_of(o.labels.begin(), o.labels.end(), [](const MapObject::LabelEvidence& e) {
    return std::isfinite(e.confidence_sum) && e.count >= 0;
  });
  return o.centroid.allFinite() && o.box_min.allFinite() && o.box_max.allFinite() && Finite({o.confidence, o.height}) &&
         o.detections >= 0 && finite_points && finite_descriptor && finite_labels && ValidTimestamp(o.first_seen_ns) &&
         ValidTimestamp(o.last_seen_ns) && o.site_id >= -1 && o.site_id <= kMaxSiteId;
}

// A grid with voxels has a voxel size the grid options allow (change.grid.voxel_size_m, with slack).
bool ValidVoxelSize(const EvidenceGridData& grid) {
  constexpr double kMinVoxelM = 1e-3, kMaxVoxelM = 1e3;
  if (!std::isfinite(grid.voxel_size) || grid.voxel_size < 0.0) return false;
  return grid.voxels.empty() || (grid.voxel_size >= kMinVoxelM && grid.voxel_size <= kMaxVoxelM);
}

std::vector<RouteFrame> ReadRoute(Reader* r) {
  std::vector<RouteFrame> route;
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    RouteFrame f;
    f.timestamp_ns = r->Value<TimestampNs>();
    f.frame_index = r->Value<std::int64_t>();
    const auto flags = r->Value<std::uint8_t>();
    const PoseRecord pose = r->Value<PoseRecord>();
    const double latitude = r->Value<double>(), longitude = r->Value<double>();
    if (flags > 3) f.frame_index = -1;  // not a flag this version writes: ValidRoute refuses the frame
    if ((flags & 1) != 0) f.pose = FromRecord(pose);
    if ((flags & 2) != 0) f.gps = Eigen::Vector2d(latitude, longitude);
    f.jpeg = r->Vector<unsigned char>();
    route.push_back(std::move(f));
  }
  return route;
}

// Frames in time order, each with a valid time and frame index, a valid pose and GPS where it has them, and
// JPEG bytes: the start-of-image marker and a frame header stating a size no larger than the patrol's camera
// (where it is known; key frames are kept at the feature scale, the others at max_width) and at most
// kMaxRouteFrameSide a side (what change.route_frames.max_width allows), so no crafted map makes the report or the
// route comparison decode and describe images larger than the flight that wrote it could have kept.
bool ValidRoute(const std::vector<RouteFrame>& route, const CameraIntrinsics& camera) {
  for (std::size_t i = 0; i < route.size(); ++i) {
    const RouteFrame& f = route[i];
    if (!ValidTimestamp(f.timestamp_ns) || f.frame_index < 0) return false;
    if (i > 0 && f.timestamp_ns < route[i - 1].timestamp_ns) return false;
    if (f.pose && !ValidPose(*f.pose)) return false;
    if (f.gps && !(std::abs(f.gps->x()) <= 90.0 && std::abs(f.gps->y()) <= 180.0)) return false;
    if (f.jpeg.size() < 4 || f.jpeg.size() > kMaxRouteJpegBytes || f.jpeg[0] != 0xFF || f.jpeg[1] != 0xD8) return false;
    std::int64_t width = 0, height = 0;
    if (!DeclaredImageSize(f.jpeg.data(), f.jpeg.size(), &width, &height) || width < 1 || height < 1 ||
        width > kMaxRouteFrameSide || height > kMaxRouteFrameSide) {
      return false;
    }
    if (camera.width > 0 && (width > camera.width || height > camera.height)) return false;
  }
  return true;
}

Status ParsePatrols(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    PatrolRecord p;
    p.flight = r->String();
    p.camera.fx = r->Value<double>(), p.camera.fy = r->Value<double>();
    p.camera.cx = r->Value<double>(), p.camera.cy = r->Value<double>();
    p.camera.width = r->Value<std::int32_t>(), p.camera.height = r->Value<std::int32_t>();
    p.feature_image_width = r->Value<std::int32_t>();
    for (const PoseRecord& v : r->Vector<PoseRecord>()) p.views.push_back(FromRecord(v));
    p.has_objects = r->Value<std::uint8_t>() != 0;
    const std::uint32_t objects = r->Value<std::uint32_t>();
    for (std::uint32_t k = 0; k < objects && !r->failed(); ++k) p.objects.push_back(ReadObject(r));
    p.grid.voxel_size = r->Value<double>();
    p.grid.voxels = r->Vector<VoxelEvidence>();
    if (version >= 4) p.grid.evicted_voxels = r->Value<std::int64_t>();
    if (version >= 5) p.depth_source = r->String();
    if (version >= 6) p.route = ReadRoute(r);
    if (version >= 7) p.timed = r->Value<std::uint8_t>() != 0;
    if (version >= 9) p.pose_source = r->String();
    if (version >= 10)
      for (double& k : p.distortion) k = r->Value<double>();
    if (version >= 11) p.source = r->String(), p.source_digest = r->String();
    if (version >= 12) {
      const std::vector<std::int32_t> site_ids = r->Vector<std::int32_t>();
      if (site_ids.size() != p.objects.size() && !r->failed()) return Corrupt(path, "site objects of " + p.flight);
      for (std::size_t k = 0; k < site_ids.size(); ++k) p.objects[k].site_id = site_ids[k];
    }
    if (r->failed()) break;
    if (!ValidFlightId(p.flight)) return Corrupt(path, "flight id of patrol " + std::to_string(i));
    if (!ValidCameraAndViews(p)) return Corrupt(path, "camera or views of patrol " + p.flight);
    for (const MapObject& object : p.objects) {
      if (!ValidObject(object)) return Corrupt(path, "object " + std::to_string(object.id) + " of patrol " + p.flight);
    }
    if (!SortedVoxels(p.grid.voxels) || !ValidVoxelSize(p.grid) || p.grid.evicted_voxels < 0 ||
        (p.depth_source != "" && p.depth_source != "images" && p.depth_source != "stereo")) {
      return Corrupt(path, "evidence grid of " + p.flight);
    }
    if (!ValidRoute(p.route, p.camera)) return Corrupt(path, "route frames of " + p.flight);
    if (!KnownPoseSource(p.pose_source)) return Corrupt(path, "pose source of " + p.flight);
    if (!ValidSource(p)) return Corrupt(path, "log of " + p.flight);
    // A second record of one flight would replace the first unseen (SetPatrol); a map never holds two.
    if (map->Patrol(p.flight) != nullptr) return Corrupt(path, "second patrol record of " + p.flight);
    map->SetPatrol(std::move(p));
  }
  return r->failed() || !r->done() ? Corrupt(path, "patrol section") : Status::Ok();
}

Status ParseVocabulary(const std::string& path, Reader* r, TopoMap* map) {
  TopoMap::VocabularyTag tag;
  tag.fingerprint = r->Value<std::uint64_t>();
  tag.name = r->String();
  if (r->failed() || !r->done()) return Corrupt(path, "vocabulary section");
  map->set_vocabulary(std::move(tag));
  return Status::Ok();
}

// Which sections a file has given so far; each may appear once.
struct SectionsSeen {
  bool nodes = false, edges = false, features = false, patrols = false, vocabulary = false;
};

Status ParseSection(const std::string& path, std::uint32_t version, const std::string& tag, const char* payload,
                    std::size_t length, TopoMap* map, SectionsSeen* seen) {
  Reader reader(payload, length);
  const auto once = [&](bool* flag) {
    const bool first = !*flag;
    *flag = true;
    return first;
  };
  if (tag == "NODE" && once(&seen->nodes)) return ParseNodes(path, &reader, map);
  if (tag == "EDGE" && seen->nodes && once(&seen->edges)) return ParseEdges(path, version, &reader, map);
  if (tag == "FEAT" && seen->nodes && once(&seen->features)) return ParseFeatures(path, version, &reader, map);
  if (tag == "PTRL" && once(&seen->patrols)) return ParsePatrols(path, version, &reader, map);
  if (tag == "VOCB" && once(&seen->vocabulary)) return ParseVocabulary(path, &reader, map);
  return Corrupt(path, "unexpected or repeated section " + tag);
}

}  // namespace

Status SaveMap(const TopoMap& map, const std::string& path) {
  AtomicFile file;
  PATROLMAP_RETURN_IF_ERROR(AtomicFile::Open(path, &file));
  std::string start(kMagic, 8);
  const std::uint32_t header[2] = {kVersion, 5};
  start.append(reinterpret_cast<const char*>(header), sizeof(header));
  PATROLMAP_RETURN_IF_ERROR(file.Write(start));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("NODE", map, NodeSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("EDGE", map, EdgeSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("FEAT", map, FeatureSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("PTRL", map, PatrolSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("VOCB", map, VocabularySection, &file));
  return file.Commit();
}

Status LoadMap(const std::string& path, TopoMap* map) {
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) return Status::NotFound(path + ": cannot read map: " + error.message());
  std::string bytes(size, '\0');
  std::ifstream(path, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(size));
  if (size < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    return Status::DataLoss(path + ": not a patrolmap map file");
  if (size < 16) return Status::DataLoss(path + ": truncated map (header incomplete)");
  std::uint32_t header[2];
  std::memcpy(header, bytes.data() + 8, sizeof(header));
  if (header[0] < kOldestVersion) {
    return Status::DataLoss(path + ": map format version " + std::to_string(header[0]) + " is not one patrolmap wrote");
  }
  if (header[0] > kVersion) {
    return Status::DataLoss(path + ": map format version " + std::to_string(header[0]) +
                            " is newer than this patrolmap reads (" + std::to_string(kVersion) + ")");
  }
  *map = TopoMap();
  std::size_t position = 16;
  SectionsSeen seen;
  for (std::uint32_t s = 0; s < header[1]; ++s) {
    if (size - position < 20)
      return Status::DataLoss(path + ": truncated map (section " + std::to_string(s) + " header)");
    const std::string tag(bytes.data() + position, 4);
    std::uint64_t length, checksum;
    std::memcpy(&length, bytes.data() + position + 4, 8);
    std::memcpy(&checksum, bytes.data() + position + 12, 8);
    position += 20;
    if (length > size - position) return Status::DataLoss(path + ": truncated map (section " + tag + ")");
    const char* payload = bytes.data() + position;
    if (Checksum(payload, length) != checksum) return Corrupt(path, "checksum of section " + tag);
    PATROLMAP_RETURN_IF_ERROR(ParseSection(path, header[0], tag, payload, length, map, &seen));
    position += length;
  }
  if (!seen.nodes || !seen.edges) return Corrupt(path, "node or edge section missing");
  if (position != size) return Corrupt(path, "trailing bytes");
  return Status::Ok();
}

}  // namespace patrolmap::graph
