// Fleet scale (issue 17): place queries of the pruned inverted index against the exhaustive one on the
// simulator's places, and merging maps.
//
// BM_SimulatedPlaceQuery needs maps of simulated patrol series: PATROLMAP_BENCH_MAPS=a.pmap:b.pmap:... (for
// example the run_3 maps of scripts/change_study.sh; skipped without). Their nodes form one database, padded
// with `distractors` vectors drawn from the shipped vocabulary's word frequencies; each verified loop closure
// between flights is a query whose matched node must come back in the top 3.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include <benchmark/benchmark.h>

#include "patrolmap/graph/map_file.h"
#include "patrolmap/graph/topo_map.h"
#include "patrolmap/vocab/database.h"
#include "patrolmap/vocab/vocabulary.h"

namespace {

using namespace patrolmap;

struct PlaceQuery {
  vocab::BowVector bow;
  vocab::EntryId self = 0, match = 0;
  std::string flight;
};

struct Places {
  std::vector<vocab::BowVector> nodes;
  std::vector<std::string> flights;  // per node: map index and flight
  std::vector<PlaceQuery> queries;
};

const Places* LoadPlaces() {
  static std::unique_ptr<Places> places;
  static bool tried = false;
  if (tried) return places.get();
  tried = true;
  const char* list = std::getenv("PATROLMAP_BENCH_MAPS");
  if (list == nullptr) return nullptr;
  places = std::make_unique<Places>();
  std::stringstream paths(list);
  std::string path;
  for (int m = 0; std::getline(paths, path, ':'); ++m) {
    graph::TopoMap map;
    if (!graph::LoadMap(path, &map).ok()) std::abort();
    const auto base = static_cast<vocab::EntryId>(places->nodes.size());
    for (int i = 0; i < map.node_count(); ++i) {
      places->nodes.push_back(map.node(i).bow);
      places->flights.push_back(std::to_string(m) + "/" + map.node(i).flight);
    }
    for (const graph::TopoMap::Edge& e : map.Edges()) {
      if (e.data.kind != graph::EdgeKind::kLoopClosure || map.node(e.a).flight == map.node(e.b).flight) continue;
      places->queries.push_back({map.node(e.a).bow, base + e.a, base + e.b, places->flights[base + e.a]});
    }
  }
  return places.get();
}

void BM_SimulatedPlaceQuery(benchmark::State& state) {
  const Places* places = LoadPlaces();
  if (places == nullptr || places->queries.empty()) {
    state.SkipWithError("set PATROLMAP_BENCH_MAPS to maps of simulated patrols");
    return;
  }
  vocab::Vocabulary vocabulary;
  if (!vocab::Vocabulary::Load(std::string(PATROLMAP_SOURCE_DIR) + "/vocab/default.pmvoc", &vocabulary).ok())
    std::abort();
  vocab::Database database(vocabulary.word_count());
  for (const vocab::BowVector& bow : places->nodes) database.Add(bow);
  const auto& idf = vocabulary.idf();
  std::vector<double> frequency(vocabulary.word_count());
  for (std::size_t w = 0; w < frequency.size(); ++w) frequency[w] = idf[w] > 0 ? std::exp(-idf[w]) : 0.0;
  std::discrete_distribution<vocab::WordId> draw(frequency.begin(), frequency.end());
  std::mt19937 rng(5);
  std::vector<vocab::WordId> words(300);
  vocab::BowVector bow;
  for (int i = 0; i < state.range(0); ++i) {
    for (auto& w : words) w = draw(rng);
    vocab::MakeBowVector(words, idf.data(), &bow);
    database.Add(bow);
  }
  vocab::QueryOptions options;
  options.max_words = static_cast<int>(state.range(1));
  options.rescored = static_cast<int>(state.range(2));
  std::vector<vocab::QueryResult> results, exact;
  const auto other_flight = [&](const PlaceQuery& q) {
    return [&](vocab::EntryId e) { return e >= places->nodes.size() || places->flights[e] != q.flight; };
  };
  std::size_t i = 0;
  for (auto _ : state) {
    const PlaceQuery& q = places->queries[i++ % places->queries.size()];
    database.Query(q.bow, 3, other_flight(q), &results, options);
    benchmark::DoNotOptimize(results.data());
  }
  int found = 0, found_exact = 0, same = 0;
  for (const PlaceQuery& q : places->queries) {
    database.Query(q.bow, 3, other_flight(q), &exact);
    database.Query(q.bow, 3, other_flight(q), &results, options);
    const auto has = [](const std::vector<vocab::QueryResult>& r, vocab::EntryId e) {
      return std::any_of(r.begin(), r.end(), [&](const vocab::QueryResult& x) { return x.entry == e; });
    };
    found += has(results, q.match);
    found_exact += has(exact, q.match);
    for (const vocab::QueryResult& e : exact) same += has(results, e.entry);
  }
  const double n = static_cast<double>(places->queries.size());
  state.counters["queries"] = n;
  state.counters["places"] = static_cast<double>(places->nodes.size());
  state.counters["recall@3"] = found / n;
  state.counters["exhaustive_recall@3"] = found_exact / n;
  state.counters["same_top3"] = same / (3 * n);
}
BENCHMARK(BM_SimulatedPlaceQuery)
    ->ArgNames({"distractors", "words", "rescored"})
    ->ArgsProduct({{0, 100000}, {0, 16, 32, 64}, {100, 300}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
