// A mapping run as the front ends ask for it (DESIGN.md, front ends): `patrolmap map`, `patrolmap patrol` and
// `patrolmap-onboard` fill a MappingRequest from their command lines and print the outcome; everything in
// between — configuration, vocabulary, the prior map, one FlightPass per flight, the map, the change report
// and the events — is wired here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "patrolmap/change/report.h"
#include "patrolmap/core/status.h"
#include "patrolmap/pipeline/change_events.h"
#include "patrolmap/pipeline/flight_pass.h"
#include "patrolmap/pipeline/map.h"

namespace patrolmap::pipeline {

// What each flight writes besides the map.
enum class FlightOutputs {
  kDetection,     // key_locations.csv, response.csv and response.svg (pipeline::WriteDetectionOutputs); to
                  // OUT, or OUT/<flight> when several logs are mapped together
  kKeyLocations,  // OUT/key_locations.csv alone (onboard: the response is not kept)
  kNone,          // nothing (every frame a node: there are no key locations)
};

struct MappingRequest {
  std::vector<std::string> sources;          // flight logs in the order they are matched, or camera:N (a device)
  std::string prior_map;                     // the map the flights extend (empty: none)
  std::string out;                           // output folder
  std::string config_path;                   // YAML configuration (empty: the defaults)
  std::vector<std::string> config_settings;  // --set KEY=VALUE over it (ApplySettings)
  std::string vocabulary_path;               // empty: the default one (FindDefaultVocabulary)
  double fps = 0.0;                          // rate of logs without timestamps [Hz] (0: their own)
  std::vector<std::string> topics;           // a bag's topics as ROLE=NAME (io::ParseTopicChoice)
  std::string poses;                         // camera poses of the (one) log from a TUM or KITTI file (io/pose_file.h)
  std::string camera;                        // the logs' camera calibration from a file (io/camera_file.h)
  std::string flight_id;                     // the (one) log's flight id instead of its own (empty: the log's)
  FlightPassOptions pass;
  DriveOptions drive;  // a live camera is never paced (it paces itself)
  // With a prior map that has a flight: append each change found while flying to OUT/events.jsonl.
  std::optional<ChangeEventOptions> events;
  FlightOutputs outputs = FlightOutputs::kDetection;
};

struct MappingOutcome {
  MapResult places;                // every flight's nodes and loop closures
  std::vector<FlightRun> flights;  // one per source (their records are in the map)
  change::ChangeReport report;     // with a prior map: its last flight against the last new one
  bool compared = false;           // whether `report` was made (and OUT/changes.* written)
  int events = 0;                  // lines written to OUT/events.jsonl
};

// Runs `request`: maps each source in turn through one database (seeded with the prior map), then writes the
// change report against the prior's last flight (OUT/changes.json, OUT/changes.html), the events, and last the
// map (OUT/map.pmap, nodes.csv, loop_closures.csv), so a failed run never replaces an earlier map. Fails
// naming the file and the problem on bad input.
Status RunMapping(const MappingRequest& request, MappingOutcome* outcome);

}  // namespace patrolmap::pipeline
