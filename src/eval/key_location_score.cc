#include "patrolmap/eval/key_location_score.h"

#include <cmath>
#include <limits>

#include "patrolmap/core/csv.h"

namespace patrolmap::eval {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

ExtremumKind KindAfter(const TruthEdge& edge) { return edge.opening ? ExtremumKind::kValley : ExtremumKind::kPeak; }

double Centre(const ExpectedSpan& span) {
  if (std::isinf(span.start_s)) return span.end_s;
  if (std::isinf(span.end_s)) return span.start_s;
  return 0.5 * (span.start_s + span.end_s);
}

// The unmatched span of the detection's kind that contains it, nearest centre first; -1 when none.
int FindSpan(const KeyLocation& node, const KeyLocationScore& score, double tolerance_s) {
  const double t = NsToSeconds(node.timestamp_ns);
  int best = -1;
  for (std::size_t i = 0; i < score.spans.size(); ++i) {
    const ExpectedSpan& span = score.spans[i];
    if (span.kind != node.kind || score.span_match[i] >= 0) continue;
    if (t < span.start_s - tolerance_s || t > span.end_s + tolerance_s) continue;
    if (best < 0 || std::abs(t - Centre(span)) < std::abs(t - Centre(score.spans[best]))) best = static_cast<int>(i);
  }
  return best;
}

// Keeps the first edge of each run of one kind.
std::vector<TruthEdge> CollapseRuns(const std::vector<TruthEdge>& edges) {
  std::vector<TruthEdge> kept;
  for (const TruthEdge& edge : edges) {
    if (kept.empty() || kept.back().opening != edge.opening) kept.push_back(edge);
  }
  return kept;
}

// Removes the two edges around the shortest inner span under min_span_s, until none is left.
std::vector<TruthEdge> MergeShortSpans(std::vector<TruthEdge> edges, double min_span_s) {
  while (edges.size() >= 2) {
    std::size_t shortest = 0;
    for (std::size_t i = 1; i + 1 < edges.size(); ++i) {
      if (edges[i + 1].timestamp_ns - edges[i].timestamp_ns <
          edges[shortest + 1].timestamp_ns - edges[shortest].timestamp_ns) {
        shortest = i;
      }
    }
    if (NsToSeconds(edges[shortest + 1].timestamp_ns - edges[shortest].timestamp_ns) >= min_span_s) break;
    edges.erase(edges.begin() + shortest, edges.begin() + shortest + 2);
  }
  return edges;
}

}  // namespace

std::vector<ExpectedSpan> ExpectedSpans(const std::vector<TruthEdge>& raw_edges, double min_span_s) {
  std::vector<ExpectedSpan> spans;
  const std::vector<TruthEdge> edges = MergeShortSpans(CollapseRuns(raw_edges), min_span_s);
  if (edges.empty()) return spans;
  const ExtremumKind before_first = edges.front().opening ? ExtremumKind::kPeak : ExtremumKind::kValley;
  spans.push_back({-kInfinity, NsToSeconds(edges.front().timestamp_ns), before_first, false});
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    spans.push_back(
        {NsToSeconds(edges[i].timestamp_ns), NsToSeconds(edges[i + 1].timestamp_ns), KindAfter(edges[i]), true});
  }
  spans.push_back({NsToSeconds(edges.back().timestamp_ns), kInfinity, KindAfter(edges.back()), false});
  return spans;
}

KeyLocationScore ScoreKeyLocations(const std::vector<KeyLocation>& detected, const std::vector<TruthEdge>& edges,
                                   const KeyLocationScoreOptions& options) {
  KeyLocationScore score;
  score.spans = ExpectedSpans(edges, options.min_span_s);
  score.span_match.assign(score.spans.size(), -1);
  score.detected = static_cast<int>(detected.size());
  for (std::size_t d = 0; d < detected.size(); ++d) {
    const int span = FindSpan(detected[d], score, options.tolerance_s);
    if (span >= 0) score.span_match[span] = static_cast<int>(d);
    score.verdicts.push_back(span >= 0 ? Verdict::kTruePositive : Verdict::kFalsePositive);
    ++(span >= 0 ? score.true_positives : score.false_positives);
  }
  for (std::size_t i = 0; i < score.spans.size(); ++i) {
    if (!score.spans[i].required) continue;
    ++score.expected;
    score.missed += score.span_match[i] < 0;
  }
  return score;
}

Status ReadTruthEdges(const std::string& log, std::vector<TruthEdge>* edges) {
  const auto parse = [edges](const CsvReader& csv, const std::vector<std::string_view>& fields, TruthEdge* edge) {
    if (fields.size() < 3) return csv.Error("expected at least 3 columns");
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[0], "timestamp [ns]", &edge->timestamp_ns));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[1], "frame_index", &edge->frame_index));
    if (fields[2] != "opening" && fields[2] != "closing") return csv.Error("kind must be opening or closing");
    if (!edges->empty() && edge->timestamp_ns < edges->back().timestamp_ns) return csv.Error("timestamps go back");
    edge->opening = fields[2] == "opening";
    return Status::Ok();
  };
  return ReadTable(log + "/groundtruth/key_locations.csv", nullptr, parse, edges);
}

Status ReadKeyLocationsCsv(const std::string& path, std::vector<KeyLocation>* key_locations) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, KeyLocation* node) {
    if (fields.size() < 5) return csv.Error("expected 5 columns");
    std::int64_t index = 0;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[0], "node", &index));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[1], "timestamp_ns", &node->timestamp_ns));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[2], "frame_index", &node->frame_index));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[3], "response", &node->response));
    if (fields[4] != "peak" && fields[4] != "valley") return csv.Error("kind must be peak or valley");
    node->node_index = static_cast<int>(index);
    node->kind = fields[4] == "peak" ? ExtremumKind::kPeak : ExtremumKind::kValley;
    return Status::Ok();
  };
  return ReadTable(path, "node", parse, key_locations);
}

}  // namespace patrolmap::eval
