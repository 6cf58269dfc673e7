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
// lies within `distance_m` (moved: both its positions). A class-agnostic one
// (from changed geometry) matches any label and is a hit when it lies within
// `distance_m` of the true object's footprint (moved: where it was, where it is,
// and in displacement), as changed space shows the part of an object that
// changed rather than its centre; the changes of objects the detector saw too
// rarely to count are optional for it (depth may see what the detector missed). Per state: precision,
// recall and F1, one-to-one matching nearest first.
//
// Geometry (per voxel, as paper 003 scores per point), only over voxels both
// evidence grids observed at least `min_observations` times (unobservable
// space is no change). A voxel truly changed (core) when it lies mostly in an
// object box of one flight (its centre a quarter voxel inside) and clear of
// the other flight's boxes, above the ground voxel; a voxel that touches a box
// of one flight only partly (the cube and the turned box share a point) is a
// tolerance band, where reporting is a hit and not reporting no miss.
// Precision = hits / reported, recall = core voxels reported / core voxels.
//
// Appearance (per region, at the places both patrols compared): an object
// change is visible in a key frame when the object stands in that flight but
// not at that place in the other (new, removed, or either end of a move), the
// flight's detector reported it within `visible_within_s` of the key frame,
// its box projected into the key frame's thumbnail covers at least
// `min_area_px` inside the image, and the registration of the two key frames
// maps its centre into the other one (the stage compares only their overlap).
// A region lies on a change when its box in
// the current (prior) key frame overlaps the current (prior) change's box by
// at least `min_overlap` of the smaller of the two. Precision = regions on a
// change / regions; recall = changes some region lies on / changes.
#pragma once

#include <map>
#include <optional>
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
  int detections = 0;                // how often the flight's detector reported it
  std::vector<TimestampNs> seen_ns;  // ... and when (ascending)
  bool Contains(const Eigen::Vector3d& point, double margin) const;
  // Whether an axis-aligned cube of half side `half` centred at `cube_centre` meets the box, or lies wholly inside
  // it; exact for a box turned by any yaw (the test along the separating axes of the two footprints).
  bool Touches(const Eigen::Vector3d& cube_centre, double half) const;
  bool Encloses(const Eigen::Vector3d& cube_centre, double half) const;
};

// Reads groundtruth/objects.csv and counts groundtruth/detections.csv of a simulated log.
Status ReadTruthObjects(const std::string& log, std::vector<TruthObject>* objects);

// The object with `id` among `objects`; null when none has it.
const TruthObject* FindId(const std::vector<TruthObject>& objects, int id);

struct ReportedObject {
  std::string state;  // persistent, new, removed, moved, unobserved
  std::string label;
  std::optional<Eigen::Vector3d> before, after;
  bool class_agnostic = false;  // from changed geometry, not a detector: matches a true object of any label
  std::string id;               // the report's id for the object ("" when it has none)
};

struct Counts {
  int true_positives = 0, false_positives = 0, false_negatives = 0;
  double Precision() const;
  double Recall() const;
  double F1() const;
};

// What became of one required true change, or of one report that matched none (ScoreObjectChanges).
struct ObjectOutcome {
  std::string state;                             // persistent, new, removed, moved
  std::string outcome;                           // found, missed (a true change), false (a report)
  std::string label;                             // the true object's; a false report's own
  std::optional<Eigen::Vector2d> before, after;  // where the true object was and is; a false report's positions
  int reported = -1;  // the report that found it, or the false report: its index in `reported`
  int id = -1;        // the true object's id (groundtruth/objects.csv); -1 for a false report
};

// How a flight saw an object from `views`, the camera poses of the truth detector's sightings of it
// (TruthObject::seen_ns): in how many its box lay whole in the image, and the camera depth of its centre (half its
// height up) in those. Tells a missed change that a depth sensor could not have ranged (seen only nearer or farther
// than its reach, or only cut by the frame's edge) from one the method lost.
struct Sightings {
  int views = 0;                             // views with the object in front of the camera
  int whole = 0;                             // ... of which its box lay whole in the image
  double nearest_m = 0.0, farthest_m = 0.0;  // camera depth over the whole ones; 0 without
};
Sightings SightingsOf(const TruthObject& object, const std::vector<CameraPoseSample>& views,
                      const CameraIntrinsics& camera, const Distortion& distortion = {});

struct ObjectChangeScore {
  std::map<std::string, Counts> by_state;  // persistent, new, removed, moved
  int unobserved = 0;                      // reported unobserved (not scored)
  // Every required true change, found or missed, and every false report, by state (in the order above) and then
  // in the order of the truth and of the reports.
  std::vector<ObjectOutcome> outcomes;
};

struct ChangeScoreOptions {
  double distance_m = 1.0;
  int min_detections = 3;
  int min_observations = 3;
  double visible_within_s = 0.25;
  double min_area_px = 100.0;  // thumbnail pixels
  double min_overlap = 0.3;
  double near_change_m = 0.5;  // false voxels this close to a changed object's box are counted apart [m]
  int min_whole_views = 3;     // a true change is observable where each end lay whole in this many views
};

ObjectChangeScore ScoreObjectChanges(const std::vector<ReportedObject>& reported,
                                     const std::vector<TruthObject>& before, const std::vector<TruthObject>& after,
                                     const ChangeScoreOptions& options);

struct GeometryScore {
  Counts voxels;
  long long observed_voxels = 0;  // observed in both grids
  // Of the false positives, those within ChangeScoreOptions::near_change_m of the box of an object that changed
  // (either flight's): a true change reported too wide, not a change where there was none.
  long long false_near_change = 0;
  double Iou() const;
};

GeometryScore ScoreGeometry(const std::vector<Eigen::Vector3i>& changed, const EvidenceGridData& before_grid,
                            const EvidenceGridData& after_grid, const std::vector<TruthObject>& before,
                            const std::vector<TruthObject>& after, const ChangeScoreOptions& options);

// The boxes, in a key frame of the flight whose objects are `here`, of the objects changed with respect to
// `other` that the key frame shows. `camera` is the thumbnail's camera (with its lens's `distortion`), `pose` the key
// frame's.
std::vector<cv::Rect2d> VisibleChangeBoxes(const std::vector<TruthObject>& here, const std::vector<TruthObject>& other,
                                           TimestampNs time_ns, const CameraPoseSample& pose,
                                           const CameraIntrinsics& camera, const ChangeScoreOptions& options,
                                           const Distortion& distortion = {});

struct VisibleChange {
  int id = 0;  // the object's
  cv::Rect2d box;
};
// VisibleChangeBoxes with the objects' ids.
std::vector<VisibleChange> VisibleChanges(const std::vector<TruthObject>& here, const std::vector<TruthObject>& other,
                                          TimestampNs time_ns, const CameraPoseSample& pose,
                                          const CameraIntrinsics& camera, const ChangeScoreOptions& options,
                                          const Distortion& distortion = {});

// Whether `to_other` (a homography) maps the box's centre inside a width x height image.
bool CentreMapsInside(const Eigen::Matrix3d& to_other, int width, int height, const cv::Rect2d& box);
// Keeps the boxes whose centre `to_other` maps inside a width x height image.
void KeepInOverlap(const Eigen::Matrix3d& to_other, int width, int height, std::vector<cv::Rect2d>* boxes);

struct PlaceTruth {
  std::vector<cv::Rect2d> prior, current;  // visible change boxes in the two key frames
};
struct RegionBoxes {
  cv::Rect2d prior, current;
};

struct AppearanceScore {
  int regions = 0, regions_on_change = 0;
  int changes = 0, changes_found = 0;
  double Precision() const;
  double Recall() const;
};

// One entry per compared place in both vectors.
AppearanceScore ScoreAppearance(const std::vector<PlaceTruth>& truth,
                                const std::vector<std::vector<RegionBoxes>>& regions,
                                const ChangeScoreOptions& options);

// Appearance along the route (change::RouteComparison). Per compared pair of route frames, the object changes
// visible in each frame (as for key frames, within the pair's overlap). A reported change lies on a change
// when one of its views' boxes overlaps a visible change's box in that view's pair; an object change (per
// side: its prior or current position) is found when some reported change lies on it in some pair.
// Precision = changes on a change / changes; recall = object changes found / object changes visible in any
// compared pair.
struct RoutePairTruth {
  std::vector<VisibleChange> prior, current;
};
struct ReportedRouteChange {
  std::vector<int> pairs;          // per view: the compared pair (index into the truth)
  std::vector<RegionBoxes> boxes;  // ... and its boxes in the pair's two frames
  double confidence = 0.0;
};
// A region the comparison found in a pair and did not report, with the step that dropped it: a higher `step`
// came later in the comparison; `step_name` names it.
struct RouteCandidate {
  int pair = -1;  // index into the truth
  RegionBoxes boxes;
  int step = 0;
  std::string step_name;
};
struct RouteScore {
  int changes = 0, changes_on_truth = 0;
  int visible = 0, found = 0;
  // Of those, the ones visible in a prior frame (an object that left, or the place a moved one left), counted
  // apart: the current frame shows only the ground or wall that was behind the object.
  int visible_in_prior = 0, found_in_prior = 0;
  // Per object change visible and not found: the name of the furthest step a candidate lying on it reached, in
  // any pair ("no_region" when none lay on it). Where recall is lost.
  std::map<std::string, int> lost_at;
  // Per reported change, in the order given: its confidence and whether it lies on an object change.
  std::vector<std::pair<double, bool>> ranked;
  double Precision() const;
  double Recall() const;
};

// How well `ranked`'s confidences put the changes that lie on an object change first: the precision at each such
// change's rank, averaged, the changes sorted by confidence with ties ranked false first (a tie tells nothing).
// 1 when every true change outranks every false one; 0 with no true change.
double AveragePrecision(std::vector<std::pair<double, bool>> ranked);
RouteScore ScoreRoute(const std::vector<RoutePairTruth>& truth, const std::vector<ReportedRouteChange>& reported,
                      const std::vector<RouteCandidate>& candidates, const ChangeScoreOptions& options);

// The fused change list (changes.json "changes": one entry per physical change, whatever channels saw it), scored
// per entry. The true changes are every object gone, come or moved between the two flights, whatever the detector
// saw; one is observable when each end the patrols could see (where it was, where it is) lay whole in the image in
// at least `min_whole_views` of its flight's views (Sightings). An entry lies on a true change when its position
// (or, moved, its prior position) lies within distance_m of the object's box where it was or where it is. A true
// change is found when an entry lies on it; an entry with a position that lies on none is false. Entries known only
// by a bearing are counted apart.
struct TrueChange {
  int id = -1;                          // groundtruth/objects.csv
  std::string state;                    // new, removed, moved
  const TruthObject* before = nullptr;  // where it was (removed, moved), in the prior flight's truth
  const TruthObject* after = nullptr;   // where it is (new, moved)
  bool observable = false;
};
std::vector<TrueChange> TrueChanges(const std::vector<TruthObject>& before, const std::vector<TruthObject>& after);

struct ReportedEntry {
  std::string id;
  std::optional<Eigen::Vector3d> position, from;
};

struct EntryScore {
  int entries = 0, bearings = 0;  // all entries; those without a position
  int true_entries = 0;           // entries with a position on a true change (the rest are false_ids)
  // True changes found (true positives) and missed, over all and over the observable ones; false positives: the
  // false entries. Precision() is of true changes, so Precision() below is per entry.
  Counts all, observable;
  double Precision() const;  // true entries / entries with a position
  double Recall(bool observable_only) const;
  double F1(bool observable_only) const;
  std::vector<std::string> false_ids;
  std::vector<int> missed_ids;  // true changes no entry lies on (groundtruth ids)
};
EntryScore ScoreEntries(const std::vector<ReportedEntry>& entries, const std::vector<TrueChange>& truth,
                        const ChangeScoreOptions& options);

// The object channel over the true changes as a whole (new, removed, moved; TrueChanges), over all and over the
// observable ones: a true change is found when ScoreObjectChanges found it (its id, its state); false positives are
// the false reports of a change (persistent ones are no change).
struct ObjectChangeTotals {
  Counts all, observable;
};
ObjectChangeTotals TotalObjectChanges(const ObjectChangeScore& score, const std::vector<TrueChange>& truth);

// Site objects (change/site_objects.h) against the truth: a map object is the true object of its label whose box
// (grown by distance_m) holds its centroid, the nearest first. Over consecutive patrols that both had detections,
// a true object both gave a map object to is tracked: kept when both carry one site id, else its id changed. A
// site id given to two true objects in one series merged them.
struct SiteIdScore {
  int tracked = 0, kept = 0, changed = 0;
  int merged = 0;              // site ids held by more than one true object
  double Persistence() const;  // kept / tracked (1 with none tracked)
};
// The true object `object` is, among `truth` (its flight's); -1 for none.
int TruthIdOf(const MapObject& object, const std::vector<TruthObject>& truth, const ChangeScoreOptions& options);
// `patrols`: per patrol with detections, in the order flown, its objects' (site id, true id) pairs.
SiteIdScore ScoreSiteIds(const std::vector<std::vector<std::pair<int, int>>>& patrols);

}  // namespace patrolmap::eval
