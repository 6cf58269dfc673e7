#include "patrolmap/graph/topo_map.h"

#include <algorithm>
#include <deque>

#include <boost/graph/breadth_first_search.hpp>

#include "patrolmap/core/status.h"

namespace patrolmap::graph {

const char* ToString(EdgeKind kind) { return kind == EdgeKind::kTraversal ? "traversal" : "loop_closure"; }

int TopoMap::AddNode(KeyFrameNode node) { return static_cast<int>(boost::add_vertex(std::move(node), graph_)); }

void TopoMap::AddEdge(int a, int b, const EdgeData& edge) {
  PATROLMAP_CHECK(a >= 0 && b >= 0 && a < node_count() && b < node_count());
  PATROLMAP_CHECK(edge.kind != EdgeKind::kLoopClosure || a != b);
  boost::add_edge(static_cast<Graph::vertex_descriptor>(a), static_cast<Graph::vertex_descriptor>(b), edge, graph_);
  edge_order_.push_back({a, b, edge});
}

int TopoMap::loop_closure_count() const {
  return static_cast<int>(std::count_if(edge_order_.begin(), edge_order_.end(),
                                        [](const Edge& e) { return e.data.kind == EdgeKind::kLoopClosure; }));
}

std::vector<TopoMap::Edge> TopoMap::Edges() const { return edge_order_; }

std::vector<int> TopoMap::Neighbours(int id) const {
  std::vector<int> neighbours;
  for (auto [it, end] = boost::adjacent_vertices(static_cast<Graph::vertex_descriptor>(id), graph_); it != end; ++it) {
    neighbours.push_back(static_cast<int>(*it));
  }
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  return neighbours;
}

std::vector<int> TopoMap::NodesOfPlace(int id) const {
  std::vector<bool> seen(node_count(), false);
  std::vector<int> place, stack = {id};
  seen[id] = true;
  while (!stack.empty()) {
    const auto v = static_cast<Graph::vertex_descriptor>(stack.back());
    stack.pop_back();
    place.push_back(static_cast<int>(v));
    for (auto [it, end] = boost::out_edges(v, graph_); it != end; ++it) {
      const int other = static_cast<int>(boost::target(*it, graph_));
      if (graph_[*it].kind != EdgeKind::kLoopClosure || seen[other]) continue;
      seen[other] = true;
      stack.push_back(other);
    }
  }
  std::sort(place.begin(), place.end());
  return place;
}

std::vector<int> TopoMap::Path(int from, int to) const {
  std::vector<Graph::vertex_descriptor> predecessor(node_count());
  for (std::size_t i = 0; i < predecessor.size(); ++i) predecessor[i] = i;
  boost::breadth_first_search(
      graph_, static_cast<Graph::vertex_descriptor>(from),
      boost::visitor(boost::make_bfs_visitor(boost::record_predecessors(predecessor.data(), boost::on_tree_edge()))));
  if (from != to && predecessor[to] == static_cast<Graph::vertex_descriptor>(to)) return {};
  std::vector<int> path = {to};
  while (path.back() != from) path.push_back(static_cast<int>(predecessor[path.back()]));
  std::reverse(path.begin(), path.end());
  return path;
}

std::vector<std::string> TopoMap::Flights() const {
  std::vector<std::string> flights;
  for (int i = 0; i < node_count(); ++i) {
    if (std::find(flights.begin(), flights.end(), node(i).flight) == flights.end()) flights.push_back(node(i).flight);
  }
  // A flight with a record but no node (a log too short for a key location) goes right after the flight
  // recorded before it: records are kept in the order flown.
  auto after = flights.begin();
  for (const PatrolRecord& record : patrols_) {
    const auto found = std::find(flights.begin(), flights.end(), record.flight);
    after = found != flights.end() ? found + 1 : flights.insert(after, record.flight) + 1;
  }
  return flights;
}

std::optional<std::pair<TimestampNs, TimestampNs>> TopoMap::FlightSpan(const std::string& flight) const {
  std::optional<std::pair<TimestampNs, TimestampNs>> span;
  const auto extend = [&span](TimestampNs t) {
    span = span ? std::make_pair(std::min(span->first, t), std::max(span->second, t)) : std::make_pair(t, t);
  };
  for (int i = 0; i < node_count(); ++i) {
    if (node(i).flight == flight) extend(node(i).timestamp_ns);
  }
  if (const PatrolRecord* record = Patrol(flight)) {
    for (const RouteFrame& frame : record->route) extend(frame.timestamp_ns);
  }
  return span;
}

void TopoMap::SetPatrol(PatrolRecord record) {
  for (PatrolRecord& existing : patrols_) {
    if (existing.flight == record.flight) return void(existing = std::move(record));
  }
  patrols_.push_back(std::move(record));
}

PatrolRecord* TopoMap::MutablePatrol(const std::string& flight) {
  return const_cast<PatrolRecord*>(static_cast<const TopoMap*>(this)->Patrol(flight));
}

const PatrolRecord* TopoMap::Patrol(const std::string& flight) const {
  for (const PatrolRecord& record : patrols_) {
    if (record.flight == flight) return &record;
  }
  return nullptr;
}

}  // namespace patrolmap::graph
