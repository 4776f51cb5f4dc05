// The reference workload for the non-Cell-Indexing methods: 10^6 points of a jittered cubic
// lattice (spacing s = 1, jitter +-0.01 s), support r = 2 s (about 33 neighbours each), building
// the structure and every CSR neighbour list with 2 threads.
//
//   build/cellsph_bench --benchmark_filter=Methods
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/neighbors/point_sets.hpp"

namespace cellsph {
namespace {

// point_sets::jittered_lattice<3, float> does not compile under -Wdouble-promotion -Werror (float
// jitter times a double inside point_sets.hpp), so the lattice is generated in double and rounded
// once to float: the same points up to the rounding of the jitter amplitude 0.01.
const std::vector<Vec<3, float>>& lattice_1e6() {
  static const std::vector<Vec<3, float>> x = [] {
    const auto d = point_sets::jittered_lattice<3, double>(1000000, 1.0, 0.01);
    std::vector<Vec<3, float>> f(d.size());
    for (std::size_t i = 0; i < d.size(); ++i)
      for (int k = 0; k < 3; ++k) f[i][k] = static_cast<float>(d[i][k]);
    return f;
  }();
  return x;
}

void BM_MethodsJitteredLattice1e6(benchmark::State& state) {
  const auto method = static_cast<Method>(state.range(0));
  const int subdivision = static_cast<int>(state.range(1));
  const auto& x = lattice_1e6();
  ScopedThreads threads(2);
  NeighborSearch<3, float> ns({.method = method, .subdivision = subdivision});
  NeighborList nl;
  double build_ms = 0, query_ms = 0;
  for (auto _ : state) {
    ns.build(x, 2.0F);
    ns.find_all(nl);
    benchmark::DoNotOptimize(nl.indices.data());
    build_ms += ns.stats().build_ms;
    query_ms += ns.stats().query_ms;
  }
  const auto iters = static_cast<double>(state.iterations());
  const SearchStats& s = ns.stats();
  state.SetLabel(std::string(method_name(method)) + " H=" + std::to_string(subdivision));
  state.counters["build_ms"] = build_ms / iters;
  state.counters["query_ms"] = query_ms / iters;
  state.counters["pairs"] = static_cast<double>(s.pairs);
  state.counters["cand_per_nb"] = static_cast<double>(s.candidates) / static_cast<double>(s.pairs);
  state.counters["memory_MB"] = static_cast<double>(s.memory_bytes) / 1048576.0;
}

// Build plus one visitor traversal (no list): find_all above traverses twice (count, then fill),
// so this is the figure to compare with a single radius search per particle.
void BM_MethodsVisitorJitteredLattice1e6(benchmark::State& state) {
  const auto method = static_cast<Method>(state.range(0));
  const int subdivision = static_cast<int>(state.range(1));
  const auto& x = lattice_1e6();
  ScopedThreads threads(2);
  NeighborSearch<3, float> ns({.method = method, .subdivision = subdivision});
  std::vector<std::uint32_t> counts(x.size());
  std::uint64_t candidates = 0;
  for (auto _ : state) {
    ns.build(x, 2.0F);
    std::fill(counts.begin(), counts.end(), 0U);
    candidates = ns.for_each_pair([&counts](std::uint32_t i, std::uint32_t, float) { ++counts[i]; });
    benchmark::DoNotOptimize(counts.data());
  }
  std::uint64_t pairs = 0;
  for (auto c : counts) pairs += c;
  state.SetLabel(std::string(method_name(method)) + " H=" + std::to_string(subdivision));
  state.counters["pairs"] = static_cast<double>(pairs);
  state.counters["cand_per_nb"] = static_cast<double>(candidates) / static_cast<double>(pairs);
}

void methods(benchmark::internal::Benchmark* b) {
  b->Args({static_cast<std::int64_t>(Method::SpatialHash), 1});
  b->Args({static_cast<std::int64_t>(Method::SpatialHash), 2});
  b->Args({static_cast<std::int64_t>(Method::SortedGrid), 1});
  b->Args({static_cast<std::int64_t>(Method::SortedGrid), 2});
  b->Args({static_cast<std::int64_t>(Method::KdTree), 1});
}

BENCHMARK(BM_MethodsJitteredLattice1e6)
    ->Apply(methods)
    ->ArgNames({"method", "H"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace cellsph

namespace cellsph {
namespace {
BENCHMARK(BM_MethodsVisitorJitteredLattice1e6)
    ->Apply(methods)
    ->ArgNames({"method", "H"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
}  // namespace
}  // namespace cellsph
