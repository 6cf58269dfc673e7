#include "patrolmap/sim/objects.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/sim/village.h"
#include "plane.h"

namespace patrolmap::sim {
namespace {

struct BlockSide {
  Eigen::Vector2d from, to, outward;
};

// The street faces of the village's two blocks (see village.h).
std::vector<BlockSide> BlockSides() {
  std::vector<BlockSide> sides;
  for (double x0 : {0.0, 28.0}) {
    const double x1 = x0 + 18.0;
    sides.push_back({{x0, 0.0}, {x1, 0.0}, {0, -1}});
    sides.push_back({{x1, 0.0}, {x1, 30.0}, {1, 0}});
    sides.push_back({{x1, 30.0}, {x0, 30.0}, {0, 1}});
    sides.push_back({{x0, 30.0}, {x0, 0.0}, {-1, 0}});
  }
  return sides;
}

double Clearance(const WorldObject& object) { return object.label == ObjectLabel::kVehicle ? 3.0 : 1.2; }

bool Overlaps(const WorldObject& candidate, const std::vector<WorldObject>& objects) {
  for (const WorldObject& other : objects) {
    if ((other.centre - candidate.centre).norm() < Clearance(other) + Clearance(candidate)) return true;
  }
  return false;
}

WorldObject DrawObject(int id, cv::RNG* rng) {
  static const std::vector<BlockSide> sides = BlockSides();
  const BlockSide& side = sides[rng->uniform(0, static_cast<int>(sides.size()))];
  WorldObject object;
  object.id = id;
  const int kind = rng->uniform(0, 10);
  object.label = kind < 5 ? ObjectLabel::kCrate : (kind < 8 ? ObjectLabel::kBarrel : ObjectLabel::kVehicle);
  const Eigen::Vector2d along = (side.to - side.from).normalized();
  object.centre = side.from + rng->uniform(1.5, 16.5) * along + rng->uniform(1.5, 3.5) * side.outward;
  object.yaw =
      std::atan2(along.y(), along.x()) + (object.label == ObjectLabel::kVehicle ? 0.0 : rng->uniform(-0.5, 0.5));
  if (object.label == ObjectLabel::kCrate) object.length = object.width = object.height = rng->uniform(0.9, 1.3);
  if (object.label == ObjectLabel::kBarrel) object.length = object.width = 0.6, object.height = 0.9;
  if (object.label == ObjectLabel::kVehicle) object.length = 4.2, object.width = 1.8, object.height = 1.5;
  object.texture_seed = rng->uniform(1, 1 << 30);
  return object;
}

// Adds an object drawn from rng that keeps clear of the others (gives up after 100 tries).
void AddClearObject(int id, cv::RNG* rng, std::vector<WorldObject>* objects) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const WorldObject object = DrawObject(id, rng);
    if (Overlaps(object, *objects)) continue;
    objects->push_back(object);
    return;
  }
}

cv::Mat ObjectTexture(const WorldObject& object) {
  cv::RNG rng(object.texture_seed);
  constexpr double kTexelsPerMetre = 60.0;
  const int columns = std::max(8, static_cast<int>(object.length * kTexelsPerMetre));
  const int rows = std::max(8, static_cast<int>(object.height * kTexelsPerMetre));
  cv::Mat image(rows, columns, CV_8UC1, cv::Scalar(rng.uniform(60, 200)));
  if (object.label == ObjectLabel::kCrate) {  // planks
    for (int y = 0; y < rows; y += rows / 5 + 1)
      cv::line(image, {0, y}, {columns, y}, cv::Scalar(rng.uniform(20, 60)), 2);
    cv::line(image, {0, 0}, {columns, rows}, cv::Scalar(rng.uniform(20, 60)), 3);
  } else if (object.label == ObjectLabel::kBarrel) {  // hoops
    for (int y : {rows / 4, rows * 3 / 4}) cv::line(image, {0, y}, {columns, y}, cv::Scalar(rng.uniform(10, 50)), 3);
  } else {  // windows and wheels
    cv::rectangle(image, cv::Rect(columns / 5, 2, columns * 3 / 5, rows / 3), cv::Scalar(rng.uniform(10, 50)),
                  cv::FILLED);
    for (int x : {columns / 5, columns * 4 / 5}) cv::circle(image, {x, rows}, rows / 4, cv::Scalar(15), cv::FILLED);
  }
  cv::Mat noise(image.size(), CV_16SC1), sum;
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 8.0);
  image.convertTo(sum, CV_16SC1);
  sum += noise;
  sum.convertTo(image, CV_8UC1);
  return image;
}

// True when a wall (of a building or of another object) crosses the line of sight from the camera to the
// object's centre below the line's height there. The object's own sides do not count.
bool Hidden(const Scene& scene, const Eigen::Vector3d& camera, const WorldObject& object) {
  const Eigen::Vector3d target(object.centre.x(), object.centre.y(), object.height / 2);
  const Eigen::Vector2d origin = camera.head<2>(), ray = target.head<2>() - origin;
  const double own = 0.5 * std::hypot(object.length, object.width) + 1e-6;
  for (const Wall& wall : scene.walls) {
    if ((0.5 * (wall.start + wall.end) - object.centre).norm() <= own) continue;
    const Eigen::Vector2d along = wall.end - wall.start, offset = wall.start - origin;
    const double denominator = Cross(ray, along);
    if (std::abs(denominator) < 1e-12) continue;
    const double t = Cross(offset, along) / denominator, u = Cross(offset, ray) / denominator;
    if (t <= 0.0 || t >= 1.0 || u < 0.0 || u > 1.0) continue;
    if (camera.z() + t * (target.z() - camera.z()) <= wall.height) return true;
  }
  return false;
}

bool ProjectBox(const WorldObject& object, const CameraIntrinsics& camera, const CameraPose& pose, cv::Rect2d* box) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const Eigen::Vector3d& corner :
       StandingBoxCorners(object.centre, object.yaw, object.length, object.width, object.height)) {
    Eigen::Vector2d pixel;
    if (!Project(camera, pose, corner, &pixel)) return false;
    x0 = std::min(x0, pixel.x()), x1 = std::max(x1, pixel.x());
    y0 = std::min(y0, pixel.y()), y1 = std::max(y1, pixel.y());
  }
  *box = cv::Rect2d(x0, y0, x1 - x0, y1 - y0) & cv::Rect2d(0, 0, camera.width, camera.height);
  return box->width >= 8.0 && box->height >= 8.0;
}

Detection FalseDetection(const CameraIntrinsics& camera, cv::RNG* rng) {
  Detection detection;
  detection.label = static_cast<ObjectLabel>(rng->uniform(0, 3));
  detection.confidence = rng->uniform(0.3, 0.7);
  const double size = rng->uniform(30.0, 120.0);
  detection.box =
      cv::Rect2d(rng->uniform(0.0, camera.width - size), rng->uniform(0.0, camera.height - size), size, size);
  const double depth = rng->uniform(4.0, 15.0);
  const cv::Point2d centre = (detection.box.tl() + detection.box.br()) * 0.5;
  detection.centroid =
      depth * Eigen::Vector3d((centre.x - camera.cx) / camera.fx, (centre.y - camera.cy) / camera.fy, 1.0);
  return detection;
}

}  // namespace

const char* ToString(ObjectLabel label) {
  switch (label) {
    case ObjectLabel::kCrate: return "crate";
    case ObjectLabel::kBarrel: return "barrel";
    case ObjectLabel::kVehicle: return "vehicle";
  }
  return "?";
}

const char* ToString(ChangeState state) {
  switch (state) {
    case ChangeState::kPersistent: return "persistent";
    case ChangeState::kNew: return "new";
    case ChangeState::kRemoved: return "removed";
    case ChangeState::kMoved: return "moved";
  }
  return "?";
}

std::vector<WorldObject> PlaceObjects(int count, std::uint32_t seed) {
  cv::RNG rng(seed * 69069u + 5u);
  std::vector<WorldObject> objects;
  for (int id = 0; id < count; ++id) AddClearObject(id, &rng, &objects);
  return objects;
}

std::vector<WorldObject> ChangeObjects(const std::vector<WorldObject>& previous, const ChangeSpec& spec,
                                       std::uint32_t seed, std::vector<ObjectChange>* changes) {
  cv::RNG rng(seed * 1664525u + 1013904223u);
  std::vector<WorldObject> next;
  changes->clear();
  int next_id = 0;
  for (const WorldObject& object : previous) {
    next_id = std::max(next_id, object.id + 1);
    if (rng.uniform(0.0, 1.0) < spec.remove_fraction) {
      changes->push_back({object.id, ChangeState::kRemoved, object.label, object.centre, object.centre});
      continue;
    }
    WorldObject moved = object;
    bool move = rng.uniform(0.0, 1.0) < spec.move_fraction;
    if (move) {
      // Along the street the object stands in: in x beside the south and north sides, else in y; the other
      // way when that spot is taken, and not at all when both are (objects never overlap).
      const bool along_x = object.centre.y() < 0.0 || object.centre.y() > 30.0;
      const double shift = rng.uniform(2.0, 6.0) * (rng.uniform(0, 2) == 0 ? -1.0 : 1.0);
      std::vector<WorldObject> others = next;
      for (const WorldObject& other : previous) {
        if (other.id != object.id) others.push_back(other);
      }
      move = false;
      for (const double sign : {1.0, -1.0}) {
        moved.centre = object.centre + sign * shift * (along_x ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1));
        if (!Overlaps(moved, others)) {
          move = true;
          break;
        }
      }
      if (!move) moved.centre = object.centre;
    }
    changes->push_back(
        {object.id, move ? ChangeState::kMoved : ChangeState::kPersistent, object.label, object.centre, moved.centre});
    next.push_back(moved);
  }
  for (int i = 0; i < spec.added; ++i) {
    const std::size_t before = next.size();
    AddClearObject(next_id++, &rng, &next);
    if (next.size() > before) {
      changes->push_back(
          {next.back().id, ChangeState::kNew, next.back().label, next.back().centre, next.back().centre});
    }
  }
  return next;
}

void AddObjects(const std::vector<WorldObject>& objects, Scene* scene) {
  for (const WorldObject& object : objects) {
    scene->textures.push_back(MakeTexture(ObjectTexture(object), 60.0));
    AddBox(object.centre, object.yaw, object.length, object.width, object.height,
           static_cast<int>(scene->textures.size()) - 1, scene);
  }
}

std::vector<Detection> DetectObjects(const std::vector<WorldObject>& objects, const Scene& scene,
                                     const CameraIntrinsics& camera, const CameraPose& pose,
                                     const DetectorOptions& options, std::uint64_t frame) {
  cv::RNG rng(frame * 2862933555777941757ull + 3037000493ull);
  const Eigen::Matrix3d camera_from_world = WorldFromCameraRotation(pose.yaw).transpose();
  std::vector<Detection> detections;
  for (const WorldObject& object : objects) {
    const Eigen::Vector3d centre(object.centre.x(), object.centre.y(), object.height / 2);
    const Eigen::Vector3d in_camera = camera_from_world * (centre - pose.position);
    Detection detection;
    if (in_camera.z() < 0.3 || in_camera.norm() > options.max_range_m) continue;
    if (!ProjectBox(object, camera, pose, &detection.box)) continue;
    if (Hidden(scene, pose.position, object)) continue;
    if (rng.uniform(0.0, 1.0) < options.miss_rate) continue;
    detection.label = object.label;
    detection.confidence = rng.uniform(0.55, 0.95);
    detection.centroid =
        in_camera + options.centroid_sigma_m * Eigen::Vector3d(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1));
    detection.truth_id = object.id;
    detections.push_back(detection);
  }
  if (rng.uniform(0.0, 1.0) < options.false_rate) detections.push_back(FalseDetection(camera, &rng));
  return detections;
}

}  // namespace patrolmap::sim
