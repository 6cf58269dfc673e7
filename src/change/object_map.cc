#include "patrolmap/change/object_map.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <unordered_set>

#include <nanoflann.hpp>
#include <opencv2/imgproc.hpp>

namespace patrolmap::change {
namespace {

double Iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double overlap = (a & b).area();
  const double total = a.area() + b.area() - overlap;
  return total > 0.0 ? overlap / total : 0.0;
}

bool IsVehicle(const std::string& label) {
  for (const char* word : {"vehicle", "car", "truck", "bus", "van"}) {
    if (label.find(word) != std::string::npos) return true;
  }
  return false;
}

// The detection's depth: the median of the box's central third.
float CentralDepth(const cv::Mat& depth_m, const cv::Rect& box) {
  const cv::Rect centre(box.x + box.width / 3, box.y + box.height / 3, std::max(1, box.width / 3),
                        std::max(1, box.height / 3));
  std::vector<float> values;
  for (int y = centre.y; y < centre.br().y; ++y) {
    for (int x = centre.x; x < centre.br().x; ++x) {
      const float d = depth_m.at<float>(y, x);
      if (d > 0.0f) values.push_back(d);
    }
  }
  if (values.empty()) return 0.0f;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Paper 000's final label: the one with the highest accumulated confidence, with its mean confidence.
void AssignFinalLabel(MapObject* object) {
  const auto top = std::max_element(object->labels.begin(), object->labels.end(),
                                    [](const auto& a, const auto& b) { return a.confidence_sum < b.confidence_sum; });
  object->label = top->label;
  object->confidence = top->confidence_sum / top->count;
}

// Folds `from` into `into`: detections, centroid and descriptor weighted by detections, points, labels.
void Absorb(double point_voxel, MapObject* into, const MapObject& from) {
  const double n = into->detections + from.detections, w = from.detections / n;
  into->centroid += w * (from.centroid - into->centroid);
  if (into->descriptor.size() == from.descriptor.size()) {
    for (std::size_t b = 0; b < into->descriptor.size(); ++b) {
      into->descriptor[b] += static_cast<float>(w * (from.descriptor[b] - into->descriptor[b]));
    }
  }
  into->box_min = into->box_min.cwiseMin(from.box_min);
  into->box_max = into->box_max.cwiseMax(from.box_max);
  into->points.insert(into->points.end(), from.points.begin(), from.points.end());
  VoxelFilter(point_voxel, &into->points);
  for (const MapObject::LabelEvidence& e : from.labels) {
    auto it = std::find_if(into->labels.begin(), into->labels.end(), [&](const auto& x) { return x.label == e.label; });
    if (it == into->labels.end()) {
      into->labels.push_back(e);
    } else {
      it->confidence_sum += e.confidence_sum;
      it->count += e.count;
    }
  }
  into->detections = static_cast<int>(n);
  into->first_seen_ns = std::min(into->first_seen_ns, from.first_seen_ns);
  into->last_seen_ns = std::max(into->last_seen_ns, from.last_seen_ns);
  AssignFinalLabel(into);
}

}  // namespace

// nanoflann's k-d tree over the points, which it reads through PointCloud (its dataset adaptor). Not in the
// anonymous namespace: the members of an externally linked type.
struct PointIndex::Tree {
  struct PointCloud {
    const std::vector<Eigen::Vector3f>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t i, std::size_t axis) const { return (*points)[i][static_cast<int>(axis)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>, PointCloud, 3>;

  explicit Tree(const std::vector<Eigen::Vector3f>& points)
      : cloud{&points}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
  PointCloud cloud;
  KdTree tree;
};

PointIndex::PointIndex(const std::vector<Eigen::Vector3f>& points) : tree_(std::make_unique<Tree>(points)) {}

PointIndex::~PointIndex() = default;

double PointIndex::PairFraction(const std::vector<Eigen::Vector3f>& query, double distance) const {
  if (query.empty() || tree_->cloud.points->empty()) return 0.0;
  const float limit = static_cast<float>(distance * distance);
  int close = 0;
  for (const Eigen::Vector3f& point : query) {
    std::uint32_t index = 0;
    float squared = 0.0f;
    if (tree_->tree.knnSearch(point.data(), 1, &index, &squared) == 1 && squared < limit) ++close;
  }
  return static_cast<double>(close) / static_cast<double>(query.size());
}

double PairFraction(const std::vector<Eigen::Vector3f>& query, const std::vector<Eigen::Vector3f>& reference,
                    double distance) {
  if (query.empty() || reference.empty()) return 0.0;
  return PointIndex(reference).PairFraction(query, distance);
}

void VoxelFilter(double voxel, std::vector<Eigen::Vector3f>* points) {
  std::unordered_set<std::uint64_t> occupied;
  occupied.reserve(points->size());
  const auto key = [voxel](const Eigen::Vector3f& p) {
    const auto cell = [voxel](float v) {
      return static_cast<std::uint64_t>(std::floor(v / voxel) + (1 << 20)) & 0x1fffff;
    };
    return cell(p.x()) << 42 | cell(p.y()) << 21 | cell(p.z());
  };
  const auto end = std::remove_if(points->begin(), points->end(),
                                  [&](const Eigen::Vector3f& p) { return !occupied.insert(key(p)).second; });
  points->erase(end, points->end());
}

std::vector<float> OrientationHistogram(const cv::Mat& image, const cv::Rect& box) {
  std::vector<float> histogram(8, 0.0f);
  const cv::Rect inside = box & cv::Rect(1, 1, image.cols - 2, image.rows - 2);
  double total = 0.0;
  for (int y = inside.y; y < inside.br().y; ++y) {
    for (int x = inside.x; x < inside.br().x; ++x) {
      const double gx = image.at<std::uint8_t>(y, x + 1) - image.at<std::uint8_t>(y, x - 1);
      const double gy = image.at<std::uint8_t>(y + 1, x) - image.at<std::uint8_t>(y - 1, x);
      const double magnitude = std::hypot(gx, gy);
      if (magnitude < 1.0) continue;
      const int bin = static_cast<int>(std::floor((std::atan2(gy, gx) + M_PI) / (2.0 * M_PI) * 8.0)) & 7;
      histogram[bin] += static_cast<float>(magnitude);
      total += magnitude;
    }
  }
  if (total > 0.0) {
    for (float& value : histogram) value = static_cast<float>(value / total);
  }
  return histogram;
}

void CumulativeHistogram(const cv::Mat& image, std::array<float, 256>* cdf) {
  std::array<double, 256> counts{};
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) ++counts[row[x]];
  }
  double sum = 0.0;
  for (int v = 0; v < 256; ++v) {
    sum += counts[v];
    (*cdf)[v] = static_cast<float>(sum / static_cast<double>(image.total()));
  }
}

float BrightnessRank(const cv::Mat& image, const cv::Rect& box, const std::array<float, 256>& cdf) {
  const cv::Rect centre =
      cv::Rect(box.x + box.width / 4, box.y + box.height / 4, std::max(1, box.width / 2), std::max(1, box.height / 2)) &
      cv::Rect(0, 0, image.cols, image.rows);
  if (centre.area() == 0) return 0.5f;
  std::vector<std::uint8_t> values;
  for (int y = centre.y; y < centre.br().y; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    values.insert(values.end(), row + centre.x, row + centre.br().x);
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return cdf[values[values.size() / 2]];
}

double PointQuantile(const std::vector<Eigen::Vector3f>& points, int axis, double q) {
  if (points.size() < 10) return 0.0;
  std::vector<float> values;
  values.reserve(points.size());
  for (const Eigen::Vector3f& p : points) values.push_back(p[axis]);
  const auto k = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1));
  std::nth_element(values.begin(), k, values.end());
  return *k;
}

double PointHeight(const std::vector<Eigen::Vector3f>& points) {
  return PointQuantile(points, 2, 0.95) - PointQuantile(points, 2, 0.05);
}

cv::Rect2d ProjectBox(const CameraIntrinsics& camera, const CameraPoseSample& pose, const Eigen::Vector3d& box_min,
                      const Eigen::Vector3d& box_max) {
  std::array<Eigen::Vector3d, 8> corners;
  for (int k = 0; k < 8; ++k) {
    corners[k] = Eigen::Vector3d((k & 1) ? box_max.x() : box_min.x(), (k & 2) ? box_max.y() : box_min.y(),
                                 (k & 4) ? box_max.z() : box_min.z());
  }
  return ProjectCorners(camera, pose, corners);
}

ObjectMapper::ObjectMapper(const ObjectMapOptions& options, const CameraIntrinsics& camera)
    : options_(options), camera_(camera) {}

bool ObjectMapper::Measure(const ObjectObservation& detection, const CameraPoseSample& pose, const cv::Mat& depth_m,
                           const cv::Mat& image, Measured* measured) const {
  const cv::Rect box = cv::Rect(detection.box) & cv::Rect(0, 0, camera_.width, camera_.height);
  if (box.area() <= 0) return false;
  const bool has_depth = !depth_m.empty() && depth_m.cols == camera_.width && depth_m.rows == camera_.height;
  double z = detection.centroid_camera ? detection.centroid_camera->z() : 0.0;
  if (!detection.centroid_camera && has_depth) z = CentralDepth(depth_m, box);
  if (!(z > 0.0) || z > options_.max_range_m) return false;
  const Eigen::Vector3d in_camera = detection.centroid_camera
                                        ? *detection.centroid_camera
                                        : Eigen::Vector3d((box.x + box.width / 2.0 - camera_.cx) / camera_.fx * z,
                                                          (box.y + box.height / 2.0 - camera_.cy) / camera_.fy * z, z);
  measured->centroid = pose.ToWorld(in_camera);
  measured->size = Eigen::Vector2d(box.width * z / camera_.fx, box.height * z / camera_.fy);
  measured->points.clear();
  // The object's points: depth pixels within its half size of the 3D centroid's depth, or without a
  // centroid within segment_depth_m of its visible surface (the box centre's median depth).
  const double half_size = 0.5 * std::max(measured->size.x(), measured->size.y());
  const double reach =
      detection.centroid_camera ? std::max(options_.segment_depth_m, half_size) : options_.segment_depth_m;
  const double surface = detection.centroid_camera ? in_camera.z() : (has_depth ? CentralDepth(depth_m, box) : 0.0);
  if (has_depth && surface > 0.0) {
    const int step =
        std::max(1, static_cast<int>(std::sqrt(box.area() / static_cast<double>(options_.max_segment_samples))));
    for (int y = box.y; y < box.br().y; y += step) {
      const float* row = depth_m.ptr<float>(y);
      for (int x = box.x; x < box.br().x; x += step) {
        const double d = row[x];
        if (d <= 0.0 || std::abs(d - surface) > reach) continue;
        const Eigen::Vector3d p((x - camera_.cx) / camera_.fx * d, (y - camera_.cy) / camera_.fy * d, d);
        measured->points.push_back(pose.ToWorld(p).cast<float>());
      }
    }
    VoxelFilter(options_.point_voxel_m, &measured->points);
  }
  if (!image.empty()) {
    measured->descriptor = OrientationHistogram(image, box);
    measured->descriptor.push_back(BrightnessRank(image, box, brightness_cdf_));
  }
  return true;
}

double ObjectMapper::SurfaceAgreement(const MapObject& object, const cv::Rect2d& box, const CameraPoseSample& pose,
                                      const cv::Mat& depth_m) const {
  if (depth_m.empty()) return 0.0;
  int seen = 0, agree = 0;
  for (const Eigen::Vector3f& point : object.points) {
    const Eigen::Vector3d c = pose.ToCamera(point.cast<double>());
    if (c.z() <= 0.1) continue;
    const int u = static_cast<int>(std::lround(camera_.fx * c.x() / c.z() + camera_.cx));
    const int v = static_cast<int>(std::lround(camera_.fy * c.y() / c.z() + camera_.cy));
    if (!box.contains(cv::Point2d(u, v)) || u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) continue;
    const float d = depth_m.at<float>(v, u);
    if (d <= 0.0f || c.z() > d + options_.pair_distance_m) continue;  // no return, or hidden behind the surface
    ++seen;
    if (d - c.z() < options_.pair_distance_m) ++agree;
  }
  return seen > 0 ? static_cast<double>(agree) / seen : 0.0;
}

int ObjectMapper::Associate(const ObjectObservation& detection, const Measured& measured, const CameraPoseSample& pose,
                            const cv::Mat& depth_m) const {
  int best = -1;
  double best_score = 0.0;
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const MapObject& object = objects_[i];
    const double distance = (object.centroid - measured.centroid).norm();
    if (distance > options_.centroid_gate_m) continue;
    double score = 0.0;
    if (!measured.points.empty() && !object.points.empty()) {
      score = PairFraction(measured.points, object.points, options_.pair_distance_m);
      // A view that reveals a new side: most of the object's points this view sees lie on the depth surface.
      if (score < options_.min_pair_fraction) {
        score = SurfaceAgreement(object, detection.box, pose, depth_m);
      }
      if (score < options_.min_pair_fraction) continue;
    } else {
      const double sigma = IsVehicle(object.label) ? options_.vehicle_sigma_m : options_.category_sigma_m;
      const double prior = std::exp(-0.5 * distance * distance / (sigma * sigma));
      const double iou = Iou(ProjectBox(camera_, pose, object.box_min, object.box_max), detection.box);
      if (prior < options_.min_category_prior || iou < options_.min_box_iou) continue;
      score = prior * iou;
    }
    if (score > best_score) best = static_cast<int>(i), best_score = score;
  }
  return best;
}

void ObjectMapper::Update(int index, const ObjectObservation& detection, Measured&& measured) {
  if (index < 0) {
    MapObject object;
    object.id = static_cast<int>(objects_.size());
    object.first_seen_ns = detection.timestamp_ns;
    object.descriptor.assign(measured.descriptor.size(), 0.0f);
    if (static_cast<int>(objects_.size()) >= options_.max_objects) ForgetOne();
    objects_.push_back(std::move(object));
    sizes_.push_back(Eigen::Vector2d::Zero());
    index = static_cast<int>(objects_.size()) - 1;
  }
  MapObject& object = objects_[index];
  const double n = ++object.detections;
  object.centroid += (measured.centroid - object.centroid) / n;
  sizes_[index] += (measured.size - sizes_[index]) / n;
  if (object.descriptor.size() == measured.descriptor.size()) {
    for (std::size_t b = 0; b < object.descriptor.size(); ++b) {
      object.descriptor[b] += static_cast<float>((measured.descriptor[b] - object.descriptor[b]) / n);
    }
  }
  object.points.insert(object.points.end(), measured.points.begin(), measured.points.end());
  VoxelFilter(options_.point_voxel_m, &object.points);
  const Eigen::Vector3d half(sizes_[index].x() / 2, sizes_[index].x() / 2, sizes_[index].y() / 2);
  object.box_min = object.centroid - half;
  object.box_max = object.centroid + half;
  object.last_seen_ns = detection.timestamp_ns;
  auto evidence = std::find_if(object.labels.begin(), object.labels.end(),
                               [&](const MapObject::LabelEvidence& e) { return e.label == detection.label; });
  if (evidence == object.labels.end()) evidence = object.labels.insert(object.labels.end(), {detection.label, 0.0, 0});
  evidence->confidence_sum += detection.confidence;
  ++evidence->count;
  AssignFinalLabel(&object);
}

// Forgets the unconfirmed object seen longest ago, or with none the object seen longest ago.
void ObjectMapper::ForgetOne() {
  const auto older = [this](const MapObject& a, const MapObject& b) {
    const bool a_unconfirmed = a.detections < options_.min_detections;
    const bool b_unconfirmed = b.detections < options_.min_detections;
    if (a_unconfirmed != b_unconfirmed) return a_unconfirmed;
    return a.last_seen_ns < b.last_seen_ns;
  };
  const auto victim = std::min_element(objects_.begin(), objects_.end(), older);
  sizes_.erase(sizes_.begin() + (victim - objects_.begin()));
  objects_.erase(victim);
  ++forgotten_;
}

void ObjectMapper::AddFrame(const std::vector<ObjectObservation>& detections, const CameraPoseSample& pose,
                            const cv::Mat& depth_m, const cv::Mat& image) {
  Measured measured;
  if (!image.empty() && !detections.empty()) CumulativeHistogram(image, &brightness_cdf_);
  for (const ObjectObservation& detection : detections) {
    if (!Measure(detection, pose, depth_m, image, &measured)) {
      ++skipped_;
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    const int object = Associate(detection, measured, pose, depth_m);
    association_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++associations_;
    Update(object, detection, std::move(measured));
  }
}

std::vector<MapObject> ObjectMapper::Finish() const {
  // Objects whose mean centroids ended up this close are one object split by a failed association
  // (two solid objects cannot stand there): merged, the one seen more often absorbing the other.
  std::vector<MapObject> merged = objects_;
  std::vector<bool> alive(merged.size(), true);
  for (std::size_t i = 0; i < merged.size(); ++i) {
    for (std::size_t j = i + 1; j < merged.size() && alive[i]; ++j) {
      if (!alive[j] || (merged[i].centroid - merged[j].centroid).norm() > options_.merge_distance_m) continue;
      const std::size_t into = merged[i].detections >= merged[j].detections ? i : j, from = i + j - into;
      Absorb(options_.point_voxel_m, &merged[into], merged[from]);
      alive[from] = false;
    }
  }
  std::vector<MapObject> kept;
  for (std::size_t i = 0; i < merged.size(); ++i) {
    if (!alive[i]) continue;
    kept.push_back(std::move(merged[i]));
    kept.back().confirmed = kept.back().detections >= options_.min_detections;
    kept.back().id = static_cast<int>(kept.size()) - 1;
    kept.back().height = PointHeight(kept.back().points);
    if (kept.back().points.size() >= 10) {  // the extent of its points, a stray one or two left out
      for (int axis = 0; axis < 3; ++axis) {
        kept.back().box_min[axis] = PointQuantile(kept.back().points, axis, 0.02);
        kept.back().box_max[axis] = PointQuantile(kept.back().points, axis, 0.98);
      }
    }
  }
  return kept;
}

}  // namespace patrolmap::change
