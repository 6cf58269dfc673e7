// Scores a change report against a simulated patrol series' ground truth.
//
// Objects: each log's groundtruth/objects.csv lists its objects (id, label,
// pose, size); an object keeps its id across flights, so the true state of
// every object between two flights follows: in both at the same place
// persistent, elsewhere moved, only in the earlier removed, only in the later
// new — as far as a patrol can know it: an object counts as seen in a flight
// when the detector reported it at least `min_detections` times there
// (groundtruth/detections.csv); a moved object seen in both flights is moved,
// seen only before removed, seen only after new; an object that stayed counts
// as persistent when seen in both. One that stayed but was seen too rarely in
// one flight is optional: reported persistent (or new, when the patrol never
// saw it before) it is no error, unreported no miss.
// A reported object is a hit when a true object of the same state and label
// lies within `distance_m` (moved: both its positions). Per state: precision,
// recall and F1, one-to-one matching nearest first.
//
// Geometry (per voxel, as paper 003 scores per point), only over voxels both
// evidence grids observed at least `min_observations` times (unobservable
// space is no change). A voxel truly changed (core) when it lies mostly in an
// object box of one flight (its centre a quarter voxel inside) and clear of
// the other flight's boxes, above the ground voxel; a voxel that touches a box
// of one flight only partly (centre within half a voxel of its faces) is a
// tolerance band, where reporting is a hit and not reporting no miss.
// Precision = hits / reported, recall = core voxels reported / core voxels.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/status.h"

namespace patrolmap::eval {

struct TruthObject {
  int id = 0;
  std::string label;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double yaw = 0.0, length = 0.0, width = 0.0, height = 0.0;
  int detections = 0;  // how often the flight's detector reported it
  bool Contains(const Eigen::Vector3d& point, double margin) const;
};

// Reads groundtruth/objects.csv and counts groundtruth/detections.csv of a simulated log.
Status ReadTruthObjects(const std::string& log, std::vector<TruthObject>* objects);

struct ReportedObject {
  std::string state;  // persistent, new, removed, moved, unobserved
  std::string label;
  std::optional<Eigen::Vector3d> before, after;
};

struct Counts {
  int true_positives = 0, false_positives = 0, false_negatives = 0;
  double Precision() const;
  double Recall() const;
  double F1() const;
};

struct ObjectChangeScore {
  std::map<std::string, Counts> by_state;  // persistent, new, removed, moved
  int unobserved = 0;                       // reported unobserved (not scored)
};

struct ChangeScoreOptions {
  double distance_m = 1.0;
  int min_detections = 3;
  int min_observations = 3;
};

ObjectChangeScore ScoreObjectChanges(const std::vector<ReportedObject>& reported, const std::vector<TruthObject>& before,
                                     const std::vector<TruthObject>& after, const ChangeScoreOptions& options);

struct GeometryScore {
  Counts voxels;
  long long observed_voxels = 0;  // observed in both grids
  double Iou() const;
};

GeometryScore ScoreGeometry(const std::vector<Eigen::Vector3i>& changed, const EvidenceGridData& before_grid,
                            const EvidenceGridData& after_grid, const std::vector<TruthObject>& before,
                            const std::vector<TruthObject>& after, const ChangeScoreOptions& options);

}  // namespace patrolmap::eval
