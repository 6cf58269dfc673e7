// Scores a run of patrolmap (the output folder of detect, map, patrol or diff) against the ground truth of the
// simulated logs it processed:
// - key locations (key_locations.csv; paper 002 Table II) against the first log;
// - loop closures (nodes.csv, loop_closures.csv; Table III) against the places of every log;
// - a change report (changes.json) against the two flights it compares: objects per state and over the true changes
//   as a whole, all and observable ones; the change list per entry; and, recomputed from the run's map.pmap with the
//   run's change options, geometry per voxel and appearance at the places and along the route.
// The scores of each part are in change_score.h, key_location_score.h and loop_closure_score.h; this wires them to a
// run's files. It sits above the pipeline (it recomputes the comparison), unlike the scores it uses.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "patrolmap/change/options.h"
#include "patrolmap/core/status.h"
#include "patrolmap/eval/change_score.h"
#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/eval/loop_closure_score.h"

namespace patrolmap::eval {

struct RunScoreOptions {
  KeyLocationScoreOptions key_locations;
  LoopClosureScoreOptions loop_closures;
  ChangeScoreOptions changes;
  change::ChangeOptions change;  // the run's, to recompute its comparison
};

// The scores of the run in folder `run` against the simulated `logs` (schema patrolmap.eval/1). NotFound when the
// folder holds none of the files above; a log or file that cannot be read fails naming it.
Status ScoreRun(const std::string& run, const std::vector<std::string>& logs, const RunScoreOptions& options,
                nlohmann::json* score);

// The tables of a ScoreRun result, for a terminal; with `spans` every expected key-location span and its match too.
std::string RunScoreTables(const nlohmann::json& score, bool spans);

}  // namespace patrolmap::eval
