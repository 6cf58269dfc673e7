// Scoring detected key locations against simulator ground truth (the paper's
// Table II: nodes, false positives, false negatives).
//
// Ground truth lists the moments a building edge crosses the camera's view
// axis: an opening (near surface to far) or a closing (far to near). The
// paper's detector marks extrema of the smoothed flow response, so between an
// opening and the next closing (the camera faces a passage) it should find one
// valley, and between a closing and the next opening (it faces a facade) one
// peak. Each such span is an expected node; a detection of the right kind
// inside a span (widened by the tolerance on both sides) is a true positive,
// every other detection a false positive, and an expected span with no
// detection a miss. Before spans are formed, a run of edges of one kind (a
// depth change in steps) counts as its first edge, and a passage or facade
// shorter than min_span_s is merged into its neighbours (a slit that short
// does not separate two facades for a detector that smooths over seconds).
// The open spans before the first and after the last edge are optional:
// matched when a detection falls there, never missed.
#pragma once

#include <string>
#include <vector>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"

namespace patrolmap::eval {

// One line of <log>/groundtruth/key_locations.csv.
struct TruthEdge {
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  bool opening = false;
};

struct ExpectedSpan {
  double start_s = 0.0;  // -inf for the span before the first edge
  double end_s = 0.0;    // +inf for the span after the last edge
  ExtremumKind kind = ExtremumKind::kPeak;
  bool required = true;
};

struct KeyLocationScoreOptions {
  double tolerance_s = 1.0;  // a span accepts detections this long before its start and after its end [s]
  // Shorter passages and facades merge into their neighbours [s]. What the
  // detector resolves depends on the depth contrast and the image footprint of
  // a gap, not on time alone: on the simulated streets it resolves 2.4 s gaps at
  // 2.5 m/s, while 2-3 s spans between houses of the village often stay below
  // the minimum change (BENCHMARKS.md reports both 2.0 and 2.5 s).
  double min_span_s = 2.0;
};

enum class Verdict { kTruePositive, kFalsePositive };

struct KeyLocationScore {
  int detected = 0;
  int expected = 0;  // required spans
  int true_positives = 0;
  int false_positives = 0;
  int missed = 0;
  std::vector<Verdict> verdicts;  // per detection
  std::vector<ExpectedSpan> spans;
  std::vector<int> span_match;  // per span: index of the matching detection or -1
  double precision() const { return detected > 0 ? static_cast<double>(true_positives) / detected : 1.0; }
  double recall() const {
    const int found = expected - missed;
    return expected > 0 ? static_cast<double>(found) / expected : 1.0;
  }
};

// Builds the spans from edges sorted by time.
std::vector<ExpectedSpan> ExpectedSpans(const std::vector<TruthEdge>& edges, double min_span_s);

KeyLocationScore ScoreKeyLocations(const std::vector<KeyLocation>& detected, const std::vector<TruthEdge>& edges,
                                   const KeyLocationScoreOptions& options = {});

// Reads <log>/groundtruth/key_locations.csv; NotFound when the log has none.
Status ReadTruthEdges(const std::string& log, std::vector<TruthEdge>* edges);

// Reads a run's key_locations.csv (as `patrolmap detect` writes it).
Status ReadKeyLocationsCsv(const std::string& path, std::vector<KeyLocation>* key_locations);

}  // namespace patrolmap::eval
