// Movable objects for patrols (crates, barrels, vehicles as textured boxes),
// the seeded changes between flights, and a simulated object detector.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/types.h"
#include "patrolmap/sim/renderer.h"
#include "patrolmap/sim/scene.h"

namespace patrolmap::sim {

enum class ObjectLabel { kCrate, kBarrel, kVehicle };
const char* ToString(ObjectLabel label);

struct WorldObject {
  int id = 0;
  ObjectLabel label = ObjectLabel::kCrate;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // on the ground [m]
  double yaw = 0.0;                                  // of the length axis [rad]
  double length = 1.0, width = 1.0, height = 1.0;    // [m]
  std::uint32_t texture_seed = 0;
};

enum class ChangeState { kPersistent, kNew, kRemoved, kMoved };
const char* ToString(ChangeState state);

// What happened to one object between two flights.
struct ObjectChange {
  int id = 0;
  ChangeState state = ChangeState::kPersistent;
  ObjectLabel label = ObjectLabel::kCrate;
  Eigen::Vector2d before = Eigen::Vector2d::Zero();  // position in the earlier flight (not for kNew)
  Eigen::Vector2d after = Eigen::Vector2d::Zero();   // position in the later flight (not for kRemoved)
};

// How the objects change from one flight to the next (each drawn from the seed).
struct ChangeSpec {
  double remove_fraction = 0.2;  // share of objects removed
  double move_fraction = 0.2;    // share of the remaining objects moved by 2-6 m along the street
  int added = 2;                 // objects added
};

// `count` objects in the street margins 1.5-3.5 m in front of the village's block facades.
std::vector<WorldObject> PlaceObjects(int count, std::uint32_t seed);

// The next flight's objects from `previous`; `changes` lists every object of either flight.
std::vector<WorldObject> ChangeObjects(const std::vector<WorldObject>& previous, const ChangeSpec& spec,
                                       std::uint32_t seed, std::vector<ObjectChange>* changes);

// Adds the objects to a scene as boxes with roofs.
void AddObjects(const std::vector<WorldObject>& objects, Scene* scene);

// A detection as the simulated detector reports it.
struct Detection {
  ObjectLabel label = ObjectLabel::kCrate;
  double confidence = 0.0;
  cv::Rect2d box;                                      // in the image [pixels]
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // in the camera frame (x right, y down, z forward) [m]
  int truth_id = -1;                                   // the object it comes from, -1 for a false detection
};

struct DetectorOptions {
  double rate_hz = 6.0;            // detections are reported for frames at about this rate
  double max_range_m = 20.0;       // objects farther than this are not detected
  double miss_rate = 0.1;          // chance that a visible object is not reported in a frame
  double false_rate = 0.03;        // chance per frame of a detection with no object behind it
  double centroid_sigma_m = 0.15;  // noise of the reported 3D centroid [m]
};

// Simulated detections of `objects` seen from `pose` (visibility: in front,
// in range, at least 8x8 pixels in the image, centre not hidden by a wall of
// a building or of another object).
// `frame` seeds the noise.
std::vector<Detection> DetectObjects(const std::vector<WorldObject>& objects, const Scene& scene,
                                     const CameraIntrinsics& camera, const CameraPose& pose,
                                     const DetectorOptions& options, std::uint64_t frame);

}  // namespace patrolmap::sim
