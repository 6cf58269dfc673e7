// Change events while flying (DESIGN.md, front ends: patrolmap-onboard --map): the flight is compared with
// the prior map's last flight as it goes, and each change found is appended to DIR/events.jsonl as one JSON
// line, so a ground station can follow:
//   appearance   a loop closure onto a prior node whose key frames differ (change/appearance)
//   object_new, object_removed, object_moved
//                the object map so far against the prior one (change/object_diff), every interval_s of
//                flight; views of the last settle_s do not count yet (the detections they bring may still
//                be coming)
//   geometry     a changed region of the evidence grid so far (change/evidence_grid), every interval_s
// An object or geometry change is sent when two checks in a row find it.
// The file is started afresh by each run. Each line carries a stable id, the flight time, the position (the camera's,
// or the object's or region's) and a confidence. A line is written with one write() to a file opened for appending, so
// it is there whole or not at all, even when the process is killed. When the flight ends, the changes of the final
// report that no event announced follow, marked "final": true (the report in changes.json is the reference).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "patrolmap/change/change_detector.h"
#include "patrolmap/change/report.h"
#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/map.h"
#include "patrolmap/pipeline/patrol_recorder.h"

namespace patrolmap::pipeline {

struct ChangeEventOptions {
  double interval_s = 5.0;  // flight time between checks of the object map and the grid [s]
  double settle_s = 5.0;    // the last views left out of the check for removed objects [s]
  // Rays each patrol must have cast through or into a voxel for a check while flying to compare it (the report
  // after the flight uses change.geometry.min_observations): near the camera the grid is still growing, and a
  // facade so far seen only at a grazing angle is passed by rays that end on it further along.
  int min_observations = 12;
  bool IsValid(std::string* error) const;
};

class ChangeMonitor {
 public:
  // Compares with flight `prior_flight` of `prior` (both outlive the monitor); appends to `path`.
  static Status Open(const graph::TopoMap* prior, const std::string& prior_flight, const Config& config,
                     const ChangeEventOptions& options, const std::string& path,
                     std::unique_ptr<ChangeMonitor>* monitor);
  ~ChangeMonitor();
  ChangeMonitor(const ChangeMonitor&) = delete;
  ChangeMonitor& operator=(const ChangeMonitor&) = delete;

  // Place stage's thread: a new node of the flight (its features found on an image `feature_width` pixels wide),
  // the camera pose there and its loop closure (may be null).
  void OnNode(const KeyFrameNode& node, int feature_width, const std::optional<CameraPoseSample>& pose,
              const MapLoopClosure* closure, const io::LogInfo& info);
  // Change stage's thread: after each step of the patrol record.
  void OnChangeStep(TimestampNs timestamp_ns, const PatrolRecorder& recorder);
  // After the flight: the final report's changes that no event announced, each with the `entry` of the report's
  // change list (`entries`) that holds it. `map` holds both flights.
  Status Close(const change::ChangeReport& report, const graph::TopoMap& map,
               const std::vector<change::ChangeItem>& entries);

  int events() const;
  const Status& status() const { return status_; }  // the first failed write, if any

  struct Event;  // one line of the file

 private:
  ChangeMonitor(const graph::TopoMap* prior, const std::string& prior_flight, const Config& config,
                const ChangeEventOptions& options, int fd);
  void Send(const Event& event, bool final_event);
  void CheckRecord(TimestampNs timestamp_ns, const PatrolRecorder& recorder);
  // Why a check holds its geometry and object changes back (the poses disagree, or the alignment is undecided: a
  // shift fits better than none, not yet by min_gain), said once each.
  void WarnHeldBack(const std::string& flight, const change::LiveFindings& found);

  const graph::TopoMap* prior_;
  std::string prior_flight_;
  const PatrolRecord* prior_record_;  // reference_, once the prior flight's record is found
  PatrolRecord reference_;
  Config config_;
  ChangeEventOptions options_;
  TimestampNs last_ns_ = 0;  // change thread until Close()
  int fd_;
  std::string path_;
  TimestampNs first_ns_ = 0, next_check_ns_ = 0;
  bool started_ = false;
  bool warned_poses_ = false;      // that the poses disagree (change thread)
  bool warned_undecided_ = false;  // that the alignment is undecided (change thread)
  // Against the prior record, with change.geometry.min_observations set to options.min_observations; it keeps the
  // shift taken while flying, so events are placed in the map's frame, as the report after the flight places them
  // (change thread). None without a prior record.
  std::optional<change::ChangeDetector> detector_;
  std::set<std::string> seen_before_;  // ids the previous check found (change thread)
  mutable std::mutex mutex_;           // the file, sent_ and status_ (two stage threads write)
  std::set<std::string> sent_;
  int events_ = 0;
  Status status_;
};

}  // namespace patrolmap::pipeline
