// Merging maps built apart (merge.h).
#include "patrolmap/pipeline/merge.h"

#include <algorithm>
#include <limits>
#include <map>

#include <spdlog/spdlog.h>

#include "patrolmap/core/files.h"
#include "patrolmap/graph/map_file.h"
#include "patrolmap/io/natural_sort.h"
#include "patrolmap/pipeline/config.h"
#include "patrolmap/pipeline/map.h"

namespace patrolmap::pipeline {
namespace {

// One flight of one input map: its nodes in order and its patrol record.
struct FlightPart {
  std::string id;  // in the merged map (renamed on a clash)
  int map = 0;     // index of the input map
  std::vector<int> nodes;
  const PatrolRecord* record = nullptr;  // may be null (a map written before patrol records)
  // When it started: its first node or route frame (kept from the log's first frame on); a flight with neither
  // sorts first.
  TimestampNs start = std::numeric_limits<TimestampNs>::min();
};

std::vector<FlightPart> FlightsOf(const graph::TopoMap& map, int index) {
  std::vector<FlightPart> parts;
  std::map<std::string, std::size_t> part_of;
  for (const std::string& flight : map.Flights()) {  // a flight may have a record and no node
    part_of.emplace(flight, parts.size());
    parts.push_back({flight, index, {}, map.Patrol(flight)});
    if (const auto span = map.FlightSpan(flight)) parts.back().start = span->first;
  }
  for (int i = 0; i < map.node_count(); ++i) parts[part_of.at(map.node(i).flight)].nodes.push_back(i);
  return parts;
}

// Gives each flight id that an earlier map already has a new one (ID-2, ID-3, ...), or fails naming both maps.
Status ResolveClashes(const MergeRequest& request, std::vector<FlightPart>* parts, MergeOutcome* outcome) {
  std::map<std::string, int> owner;
  for (const FlightPart& part : *parts) owner.emplace(part.id, part.map);
  std::map<std::string, int> seen;
  for (FlightPart& part : *parts) {
    const auto [it, first] = seen.emplace(part.id, part.map);
    if (first) continue;
    if (!request.rename_clashes) {
      return Status::InvalidArgument("flight " + part.id + " is in both " + request.maps[it->second] + " and " +
                                     request.maps[part.map] +
                                     ": merge each flight once, or rename the later ones with --rename-clashes");
    }
    std::string id;
    for (int k = 2; id.empty() || owner.count(id) > 0; ++k) id = part.id + "-" + std::to_string(k);
    owner.emplace(id, part.map);
    seen.emplace(id, part.map);
    outcome->renamed.emplace_back(request.maps[part.map] + ": " + part.id, id);
    part.id = id;
  }
  return Status::Ok();
}

// The merge order: by start, then by id.
void SortFlights(std::vector<FlightPart>* parts) {
  std::stable_sort(parts->begin(), parts->end(), [](const FlightPart& a, const FlightPart& b) {
    if (a.start != b.start) return a.start < b.start;
    return io::NaturalLess(a.id, b.id);
  });
}

Status LoadInputs(const MergeRequest& request, const vocab::Vocabulary& vocabulary, const std::string& vocabulary_path,
                  std::vector<graph::TopoMap>* maps) {
  maps->resize(request.maps.size());
  for (std::size_t i = 0; i < request.maps.size(); ++i) {
    const std::string& path = request.maps[i];
    PATROLMAP_RETURN_IF_ERROR(graph::LoadMap(path, &(*maps)[i]));
    const graph::TopoMap& map = (*maps)[i];
    PATROLMAP_RETURN_IF_ERROR(CheckVocabulary(map, path, vocabulary, vocabulary_path));
    if (map.vocabulary().fingerprint == 0) {
      spdlog::warn("{}: records no vocabulary (a map older than format 3): assumed to be {}", path, vocabulary_path);
    }
    for (int n = 0; n < map.node_count(); ++n) PATROLMAP_RETURN_IF_ERROR(CheckNodeFits(map, path, n, vocabulary));
    spdlog::info("{}: {} flights, {} nodes", path, map.Flights().size(), map.node_count());
  }
  return Status::Ok();
}

// The site ids of a record of input map `map` in the merged map: numbered 1, 2, ... as they first appear in the
// merge order, one input map's object keeping one id (an object of a map without site ids, a new one).
void RenumberSiteObjects(int map, std::map<std::pair<int, int>, int>* site_ids, PatrolRecord* record) {
  for (MapObject& o : record->objects) {
    const int next = static_cast<int>(site_ids->size()) + 1;
    // An object without a site id is one of its own: a key no other object has.
    const std::pair<int, int> key = o.site_id >= 0 ? std::make_pair(map, o.site_id) : std::make_pair(map, -next);
    o.site_id = site_ids->emplace(key, next).first->second;
  }
}

// Recognises every node again in the merge order and builds the merged map.
graph::TopoMap Replay(const std::vector<graph::TopoMap>& maps, const std::vector<FlightPart>& parts,
                      const vocab::Vocabulary& vocabulary, const place::PlaceOptions& options,
                      const MergeRequest& request, MergeOutcome* outcome) {
  place::PlaceRecognizer recognizer(&vocabulary, options);
  graph::TopoMap merged;
  std::vector<int> map_of;                                    // input map of each merged node
  std::vector<std::pair<int, place::Verification>> closures;  // (query node, accepted verification)
  std::map<std::pair<int, int>, int> site_ids;                // (input map, its site id) -> the merged map's
  std::int64_t total = 0;
  for (const FlightPart& part : parts) total += static_cast<std::int64_t>(part.nodes.size());
  for (const FlightPart& part : parts) {
    const bool timed = part.record == nullptr || part.record->timed;
    for (const int n : part.nodes) {
      KeyFrameNode node = maps[part.map].node(n);
      node.flight = part.id;
      place::PlaceResult result;
      recognizer.AddDescribedKeyFrame(node, timed, &result);
      outcome->seconds_query += result.seconds_query;
      outcome->seconds_verify += result.seconds_verify;
      const int id = merged.AddNode(std::move(node));
      PATROLMAP_CHECK(id == result.node);  // the recognizer and the map number nodes alike
      map_of.push_back(part.map);
      if (id > 0 && merged.node(id - 1).flight == part.id) merged.AddEdge(id - 1, id, graph::EdgeData{});
      if (result.match) {
        closures.emplace_back(id, *result.match);
        outcome->across_maps += map_of[result.match->node] != part.map;
      }
      if (request.progress) request.progress(id + 1, total);
    }
    if (part.record != nullptr) {
      PatrolRecord record = *part.record;
      record.flight = part.id;
      RenumberSiteObjects(part.map, &site_ids, &record);
      merged.SetPatrol(std::move(record));
    }
  }
  // After every traversal, as a mapping run adds them (BuildTopoMap), so the layout sees the same graph.
  for (const auto& [query, v] : closures) {
    merged.AddEdge(query, v.node,
                   {graph::EdgeKind::kLoopClosure, v.bow_score, v.matched_fraction, v.inliers, v.log_nfa});
  }
  outcome->flights = static_cast<int>(parts.size());
  outcome->nodes = merged.node_count();
  outcome->loop_closures = static_cast<int>(closures.size());
  return merged;
}

}  // namespace

Status RunMerge(const MergeRequest& request, MergeOutcome* outcome) {
  *outcome = MergeOutcome();
  if (request.maps.empty()) return Status::InvalidArgument("no map given");
  for (const std::string& path : request.maps) {
    PATROLMAP_RETURN_IF_ERROR(RefuseOverwritingInput(request.out + "/map.pmap", path, "map"));
  }
  Config config;
  PATROLMAP_RETURN_IF_ERROR(LoadCheckedConfig(request.config_path, request.config_settings, &config));
  vocab::Vocabulary vocabulary;
  std::string vocabulary_path;
  PATROLMAP_RETURN_IF_ERROR(LoadSiftVocabulary(request.vocabulary_path, &vocabulary, &vocabulary_path));
  std::vector<graph::TopoMap> maps;
  PATROLMAP_RETURN_IF_ERROR(LoadInputs(request, vocabulary, vocabulary_path, &maps));
  std::vector<FlightPart> parts;
  for (std::size_t i = 0; i < maps.size(); ++i) {
    for (FlightPart& part : FlightsOf(maps[i], static_cast<int>(i))) parts.push_back(std::move(part));
  }
  PATROLMAP_RETURN_IF_ERROR(ResolveClashes(request, &parts, outcome));
  SortFlights(&parts);
  graph::TopoMap merged = Replay(maps, parts, vocabulary, config.place, request, outcome);
  merged.set_vocabulary(TagOf(vocabulary, vocabulary_path));
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(request.out));
  return SaveMapRun(&merged, request.out, "", config.map);
}

}  // namespace patrolmap::pipeline
