#include "map_codec.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <opencv2/core.hpp>

#include "patrolmap/core/csv.h"
#include "patrolmap/core/flight_id.h"
#include "patrolmap/core/image_header.h"
#include "patrolmap/vocab/descriptors.h"

namespace patrolmap::graph {
namespace {

constexpr std::size_t kMaxRouteJpegBytes = 16u << 20;
constexpr int kMaxRouteFrameSide = 2048;  // change.route_frames.max_width's largest value
constexpr int kMaxThumbnailSide = 4096;

}  // namespace

void Writer::String(const std::string& text) {
  Value(static_cast<std::uint32_t>(text.size()));
  bytes_->append(text);
}

void Writer::Mat(const cv::Mat& mat) {
  const cv::Mat continuous = mat.isContinuous() ? mat : mat.clone();
  Value(static_cast<std::int32_t>(mat.type()));
  Value(static_cast<std::int32_t>(mat.rows));
  Value(static_cast<std::int32_t>(mat.cols));
  bytes_->append(reinterpret_cast<const char*>(continuous.data), continuous.total() * continuous.elemSize());
}

std::string Reader::String() {
  const std::uint32_t length = Value<std::uint32_t>();
  if (!Take(length)) return {};
  return std::string(data_ + position_ - length, length);
}

cv::Mat Reader::Mat() {
  const int type = Value<std::int32_t>(), rows = Value<std::int32_t>(), cols = Value<std::int32_t>();
  if (failed_ || rows < 0 || cols < 0 || (type != CV_8UC1 && type != CV_32FC1)) return failed_ = true, cv::Mat();
  // The bytes must be there before anything is allocated (a header may claim 2^31 x 2^31).
  const std::size_t bytes = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) * (type == CV_8UC1 ? 1 : 4);
  if (bytes > size_ - position_) return failed_ = true, cv::Mat();
  cv::Mat mat(rows, cols, type);
  if (!Take(bytes)) return cv::Mat();
  if (bytes > 0) std::memcpy(mat.data, data_ + position_ - bytes, bytes);
  return mat;
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

std::vector<PoseRecord> ToRecords(const std::vector<CameraPoseSample>& poses) {
  std::vector<PoseRecord> records;
  records.reserve(poses.size());
  for (const CameraPoseSample& pose : poses) records.push_back(ToRecord(pose));
  return records;
}

std::vector<CameraPoseSample> FromRecords(const std::vector<PoseRecord>& records) {
  std::vector<CameraPoseSample> poses;
  poses.reserve(records.size());
  for (const PoseRecord& record : records) poses.push_back(FromRecord(record));
  return poses;
}

void WriteFeatures(const KeyFrameNode& n, Writer* w) {
  w->Vector(n.points);
  w->Mat(n.descriptors);
  w->Vector(n.bow.words);
  w->Vector(n.bow.weights);
}

void ReadFeatures(Reader* r, KeyFrameNode* n) {
  n->points = r->Vector<cv::Point2f>();
  n->descriptors = r->Mat();
  n->bow.words = r->Vector<vocab::WordId>();
  n->bow.weights = r->Vector<float>();
}

void WriteObjectShape(const MapObject& o, Writer* w) {
  for (const Eigen::Vector3d* v : {&o.box_min, &o.box_max}) {
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
}

void ReadObjectShape(Reader* r, MapObject* o) {
  for (Eigen::Vector3d* v : {&o->box_min, &o->box_max}) {
    for (int k = 0; k < 3; ++k) (*v)[k] = r->Value<double>();
  }
  o->points = r->Vector<Eigen::Vector3f>();
  o->descriptor = r->Vector<float>();
  o->height = r->Value<double>();
  const std::uint32_t labels = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < labels && !r->failed(); ++i) {
    MapObject::LabelEvidence e;
    e.label = r->String();
    e.confidence_sum = r->Value<double>();
    e.count = r->Value<std::int32_t>();
    o->labels.push_back(e);
  }
}

Status Corrupt(const std::string& path, const std::string& what) {
  return Status::DataLoss(path + ": corrupt map (" + what + ")");
}

bool Finite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// Flight ids as readers keep them (core/flight_id.h); maps written before ids were cut at 200 bytes hold longer ones.
bool ValidFlightId(const std::string& id) { return IsValidFlightId(id, 1000); }

bool ValidNodeValues(const KeyFrameNode& n) {
  const bool gps_ok = !n.gps || (std::abs((*n.gps)[0]) <= 90.0 && std::abs((*n.gps)[1]) <= 180.0);
  return ValidFlightId(n.flight) && ValidTimestamp(n.timestamp_ns) && n.frame_index >= 0 && gps_ok &&
         Finite({n.layout.x(), n.layout.y(), n.heading});
}

bool ValidThumbnail(const cv::Mat& t) {
  return !t.empty() && t.type() == CV_8UC1 && t.cols <= kMaxThumbnailSide && t.rows <= kMaxThumbnailSide;
}

bool ValidFeatures(const KeyFrameNode& n) {
  return n.bow.words.size() == n.bow.weights.size() &&
         (n.descriptors.empty() || static_cast<std::size_t>(n.descriptors.rows) == n.points.size()) &&
         vocab::IsStoredDescriptorKind(n.descriptors) &&
         std::all_of(n.points.begin(), n.points.end(), [](const cv::Point2f& p) { return std::isfinite(p.x + p.y); }) &&
         (n.descriptors.depth() != CV_32F || cv::checkRange(n.descriptors)) &&
         std::all_of(n.bow.weights.begin(), n.bow.weights.end(), [](float w) { return std::isfinite(w) && w >= 0; });
}

bool ValidEdge(const EdgeData& e, int a, int b, int nodes) {
  return a >= 0 && b >= 0 && a < nodes && b < nodes && a != b && Finite({e.bow_score, e.matched_fraction, e.log_nfa}) &&
         e.bow_score >= 0.0 && e.matched_fraction >= 0.0 && e.inliers >= 0;
}

// A patrol's log as the pipeline records it: printable text, and a digest of 16 hex digits (or none).
bool ValidSource(const PatrolRecord& p) {
  const std::string& d = p.source_digest;
  return p.source.size() <= 4096 && PrintableText(p.source) == p.source &&
         (d.empty() || (d.size() == 16 && std::all_of(d.begin(), d.end(), [](char c) {
                          return std::isxdigit(static_cast<unsigned char>(c)) != 0;
                        })));
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
bool ValidGrid(const PatrolRecord& p) {
  constexpr double kMinVoxelM = 1e-3, kMaxVoxelM = 1e3;
  const EvidenceGridData& grid = p.grid;
  if (!std::isfinite(grid.voxel_size) || grid.voxel_size < 0.0 || grid.evicted_voxels < 0) return false;
  if (!grid.voxels.empty() && (grid.voxel_size < kMinVoxelM || grid.voxel_size > kMaxVoxelM)) return false;
  return SortedVoxels(grid.voxels) && KnownDepthSource(p.depth_source);
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

Status CheckPatrolRecord(const std::string& path, const PatrolRecord& p) {
  if (!ValidFlightId(p.flight)) return Corrupt(path, "flight id of a patrol record");
  if (!ValidCameraAndViews(p)) return Corrupt(path, "camera or views of patrol " + p.flight);
  for (const MapObject& object : p.objects) {
    if (!ValidObject(object)) return Corrupt(path, "object " + std::to_string(object.id) + " of patrol " + p.flight);
  }
  if (!ValidGrid(p)) return Corrupt(path, "evidence grid of " + p.flight);
  if (!ValidRoute(p.route, p.camera)) return Corrupt(path, "route frames of " + p.flight);
  if (!KnownPoseSource(p.pose_source)) return Corrupt(path, "pose source of " + p.flight);
  if (!ValidSource(p)) return Corrupt(path, "log of " + p.flight);
  return Status::Ok();
}

}  // namespace patrolmap::graph
