#include "patrolmap/eval/loop_closure_score.h"

#include <cmath>

#include "patrolmap/core/csv.h"

namespace patrolmap::eval {
namespace {

bool SamePlace(const Place& a, const Place& b, const LoopClosureScoreOptions& options) {
  const double distance = std::hypot(a.x - b.x, a.y - b.y);
  const double heading = std::abs(std::remainder(a.yaw - b.yaw, 2 * M_PI)) * 180.0 / M_PI;
  return distance <= options.radius_m && heading <= options.max_heading_deg;
}

// True when node `earlier` comes before `query` far enough to be a loop closure.
bool Before(const NodeRecord& earlier, int earlier_flight, const NodeRecord& query, int query_flight,
            double min_gap_s) {
  if (earlier_flight != query_flight) return earlier_flight < query_flight;
  return NsToSeconds(query.timestamp_ns - earlier.timestamp_ns) >= min_gap_s;
}

// Index of each node's flight in order of first appearance.
std::vector<int> FlightOrder(const std::vector<NodeRecord>& nodes) {
  std::map<std::string, int> order;
  std::vector<int> flight_of;
  for (const NodeRecord& node : nodes) {
    const auto inserted = order.emplace(node.flight, static_cast<int>(order.size()));
    flight_of.push_back(inserted.first->second);
  }
  return flight_of;
}

Status ParseInt(const CsvReader& csv, std::string_view field, const char* column, int* value) {
  std::int64_t wide = 0;
  PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(field, column, &wide));
  *value = static_cast<int>(wide);
  return Status::Ok();
}

}  // namespace

LoopClosureScore ScoreLoopClosures(const std::vector<NodeRecord>& nodes, const std::vector<Place>& places,
                                   const std::vector<LoopClosureRecord>& closures,
                                   const LoopClosureScoreOptions& options) {
  LoopClosureScore score;
  score.nodes = static_cast<int>(nodes.size());
  const std::vector<int> flight = FlightOrder(nodes);
  std::map<int, std::size_t> index_of;
  for (std::size_t i = 0; i < nodes.size(); ++i) index_of[nodes[i].node] = i;
  std::vector<bool> possible(nodes.size(), false), found(nodes.size(), false);
  std::vector<int> earlier(nodes.size(), -1);
  for (std::size_t q = 0; q < nodes.size(); ++q) {
    for (std::size_t e = 0; e < nodes.size() && !possible[q]; ++e) {
      possible[q] = Before(nodes[e], flight[e], nodes[q], flight[q], options.min_gap_s) &&
                    SamePlace(places[e], places[q], options);
      if (possible[q]) earlier[q] = static_cast<int>(e);
    }
  }
  for (const LoopClosureRecord& closure : closures) {
    const auto query = index_of.find(closure.query_node), matched = index_of.find(closure.matched_node);
    const bool known = query != index_of.end() && matched != index_of.end();
    const bool correct = known && SamePlace(places[query->second], places[matched->second], options);
    score.correct.push_back(correct);
    ++(correct ? score.true_positives : score.false_positives);
    if (correct) found[query->second] = true;
  }
  score.reported = static_cast<int>(closures.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    score.possible += possible[i];
    score.found += possible[i] && found[i];
    if (possible[i] && !found[i]) score.missed.emplace_back(static_cast<int>(i), earlier[i]);
  }
  return score;
}

Status ReadPlaces(const std::string& log, std::vector<Place>* places_by_frame) {
  const auto parse = [places_by_frame](const CsvReader& csv, const std::vector<std::string_view>& fields,
                                       Place* place) {
    if (fields.size() < 6) return csv.Error("expected 6 columns");
    std::int64_t frame = 0;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[1], "frame_index", &frame));
    if (frame != static_cast<std::int64_t>(places_by_frame->size())) return csv.Error("frames must run 0, 1, 2, ...");
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[2], "x [m]", &place->x));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[3], "y [m]", &place->y));
    return csv.ParseDouble(fields[5], "camera_yaw [rad]", &place->yaw);
  };
  return ReadTable(log + "/groundtruth/places.csv", nullptr, parse, places_by_frame);
}

Status ReadNodesCsv(const std::string& path, std::vector<NodeRecord>* nodes) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, NodeRecord* node) {
    if (fields.size() < 4) return csv.Error("expected node,flight,timestamp_ns,frame_index");
    PATROLMAP_RETURN_IF_ERROR(ParseInt(csv, fields[0], "node", &node->node));
    node->flight = std::string(fields[1]);
    PATROLMAP_RETURN_IF_ERROR(csv.ParseInt64(fields[2], "timestamp_ns", &node->timestamp_ns));
    return csv.ParseInt64(fields[3], "frame_index", &node->frame_index);
  };
  return ReadTable(path, "node", parse, nodes);
}

Status ReadLoopClosuresCsv(const std::string& path, std::vector<LoopClosureRecord>* closures) {
  const auto parse = [](const CsvReader& csv, const std::vector<std::string_view>& fields, LoopClosureRecord* row) {
    if (fields.size() < 2) return csv.Error("expected query_node,matched_node,...");
    PATROLMAP_RETURN_IF_ERROR(ParseInt(csv, fields[0], "query_node", &row->query_node));
    return ParseInt(csv, fields[1], "matched_node", &row->matched_node);
  };
  return ReadTable(path, "query_node", parse, closures);
}

}  // namespace patrolmap::eval
