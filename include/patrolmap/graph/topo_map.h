// The topological map (DESIGN.md, graph stage): nodes are key locations (KeyFrameNode, the type place recognition
// gives), edges are traversals (consecutive nodes of one flight) and loop closures (the same place, within or across
// flights), on Boost.Graph with bundled properties.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <boost/graph/adjacency_list.hpp>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "patrolmap/core/key_frame_node.h"
#include "patrolmap/core/patrol_data.h"
#include "patrolmap/core/types.h"
#include "patrolmap/vocab/bow.h"

namespace patrolmap::graph {

enum class EdgeKind : std::uint8_t { kTraversal = 0, kLoopClosure = 1 };
const char* ToString(EdgeKind kind);

struct EdgeData {
  EdgeKind kind = EdgeKind::kTraversal;
  double bow_score = 0.0;  // loop closures: verification scores
  double matched_fraction = 0.0;
  int inliers = 0;
  double log_nfa = 0.0;  // a-contrario number of false alarms, log10 (map format 3 on; 0 before)
};

class TopoMap {
 public:
  using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS, KeyFrameNode, EdgeData>;

  // Adds a node; ids are 0, 1, 2, ... in order.
  int AddNode(KeyFrameNode node);
  // Adds an edge between existing nodes; a loop closure needs two distinct nodes.
  void AddEdge(int a, int b, const EdgeData& edge);

  int node_count() const { return static_cast<int>(boost::num_vertices(graph_)); }
  int edge_count() const { return static_cast<int>(boost::num_edges(graph_)); }
  int loop_closure_count() const;
  const KeyFrameNode& node(int id) const { return graph_[static_cast<Graph::vertex_descriptor>(id)]; }
  KeyFrameNode& mutable_node(int id) { return graph_[static_cast<Graph::vertex_descriptor>(id)]; }

  struct Edge {
    int a = 0, b = 0;
    EdgeData data;
  };
  std::vector<Edge> Edges() const;                // in insertion order
  std::vector<int> Neighbours(int id) const;      // ascending, each once
  std::vector<int> NodesOfPlace(int id) const;    // nodes joined to `id` by loop closures, `id` included, ascending
  std::vector<int> Path(int from, int to) const;  // fewest edges, both ends included; empty when unreachable
  // Every flight, in the order flown: by first node, and a flight with a patrol record but no node (too short
  // for a key location) after the flight recorded before it.
  std::vector<std::string> Flights() const;
  // The first and last time of a flight's nodes and route frames; none when it has neither.
  std::optional<std::pair<TimestampNs, TimestampNs>> FlightSpan(const std::string& flight) const;

  // What each patrol keeps for change detection (object map, evidence grid,
  // views); at most one record per flight, replaced when set again.
  void SetPatrol(PatrolRecord record);
  const PatrolRecord* Patrol(const std::string& flight) const;  // nullptr when the flight has none
  PatrolRecord* MutablePatrol(const std::string& flight);
  const std::vector<PatrolRecord>& patrols() const { return patrols_; }

  // The vocabulary the nodes' bag-of-words vectors were made with (Vocabulary::Fingerprint, and the file
  // name for messages); fingerprint 0 when unknown (maps of format version 2 and older).
  struct VocabularyTag {
    std::uint64_t fingerprint = 0;
    std::string name;
  };
  const VocabularyTag& vocabulary() const { return vocabulary_; }
  void set_vocabulary(VocabularyTag tag) { vocabulary_ = std::move(tag); }

 private:
  Graph graph_;
  std::vector<Edge> edge_order_;
  std::vector<PatrolRecord> patrols_;
  VocabularyTag vocabulary_;
};

}  // namespace patrolmap::graph
