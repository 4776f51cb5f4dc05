// Cell Indexing on the reference case: 10^6 points of a jittered cubic lattice (spacing 1,
// jitter 0.01), r = 2 (about 33 neighbours each), structure + all CSR lists with 2 threads.
// Also our radix sort against std::sort on 10^6 keys.
//
// Time is wall clock; the CPU column is the whole process (all threads). On a shared machine run
// with OMP_WAIT_POLICY=passive so that CPU time counts work, not threads spinning at barriers.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/neighbors/cell_index.hpp"
#include "cellsph/neighbors/point_sets.hpp"
#include "cellsph/neighbors/radix_sort.hpp"

namespace cellsph {
namespace {

const std::vector<Vec<3, float>>& lattice_1e6() {
  static const auto x = point_sets::jittered_lattice<3, float>(1000000, 1.0f, 0.01f);
  return x;
}

// The other sets, r = 2 spacings: uniform random points (in random order), the same kind of
// points sorted into cell order, and eight Gaussian blobs (clustered).
const std::vector<Vec<3, float>>& uniform_1e6() {
  static const auto x = point_sets::uniform_random<3, float>(1000000, 1.0f);
  return x;
}
const std::vector<Vec<3, float>>& uniform_cells_1e6() {
  static const auto x = point_sets::uniform_in_cell_order<3, float>(1000000, 1.0f);
  return x;
}
const std::vector<Vec<3, float>>& clustered_1e6() {
  static const auto x = point_sets::clustered<3, float>(1000000, 1.0f);
  return x;
}
const std::vector<Vec<3, float>>& point_set(std::int64_t set) {
  switch (set) {
    case 0:
      return lattice_1e6();
    case 1:
      return uniform_1e6();
    case 2:
      return uniform_cells_1e6();
    default:
      return clustered_1e6();
  }
}

// Build + find_all, as `cellsph neighbors` runs it, on warm lists (reused across iterations).
// Args: subdivision H; set (0 lattice, 1 uniform, 2 uniform in cell order, 3 clustered); sorted (1: rows
// ascending, the default; 0: rows in the search's own order, as TreeNSearch leaves them).
void BM_CellIndexBuildAndLists(benchmark::State& state) {
  ScopedThreads threads(2);
  const auto& x = point_set(state.range(1));
  const std::vector<float> h(x.size(), 2.0f);
  CellIndex<3, float> ci({.method = Method::CellIndex,
                          .subdivision = static_cast<int>(state.range(0)),
                          .sorted_rows = state.range(2) != 0});
  NeighborList nl;
  double build_ms = 0, query_ms = 0;
  std::uint64_t cand = 0;
  for (auto _ : state) {
    Stopwatch sw;
    ci.build(x, h);
    build_ms += sw.ms();
    sw.reset();
    cand = ci.find_all(nl);
    query_ms += sw.ms();
    benchmark::DoNotOptimize(nl.indices.data());
  }
  const auto it = static_cast<double>(state.iterations());
  state.counters["build_ms"] = build_ms / it;
  state.counters["query_ms"] = query_ms / it;
  state.counters["pairs"] = static_cast<double>(nl.pairs());
  state.counters["cand_per_nb"] = static_cast<double>(cand) / static_cast<double>(nl.pairs());
  state.counters["cells"] = static_cast<double>(ci.cell_count());
  state.counters["mask"] = static_cast<double>(ci.mask_size());
  state.counters["struct_MB"] = static_cast<double>(ci.memory_bytes()) / 1e6;
  state.counters["lists_MB"] = static_cast<double>(nl.memory_bytes()) / 1e6;
}
BENCHMARK(BM_CellIndexBuildAndLists)
    ->ArgNames({"H", "set", "sorted"})
    ->Args({1, 0, 1})
    ->Args({2, 0, 1})
    ->Args({3, 0, 1})
    ->Args({1, 1, 1})
    ->Args({1, 2, 1})
    ->Args({1, 3, 1})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({1, 2, 0})
    ->Args({1, 3, 0})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The count-only scan of the same structure (find_all's first traversal alone: every distance test, one
// count per particle, no list written), the floor the issue measures the lists against.
void BM_CellIndexCountOnly(benchmark::State& state) {
  ScopedThreads threads(2);
  const auto& x = lattice_1e6();
  const std::vector<float> h(x.size(), 2.0f);
  CellIndex<3, float> ci({.method = Method::CellIndex, .subdivision = 1});
  ci.build(x, h);
  std::vector<std::uint64_t> counts;
  std::uint64_t pairs = 0;
  for (auto _ : state) {
    pairs = ci.count_pairs(counts);
    benchmark::DoNotOptimize(counts.data());
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_CellIndexCountOnly)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// Fresh output lists every iteration: includes the page faults of a first allocation.
void BM_CellIndexBuildAndFreshLists(benchmark::State& state) {
  ScopedThreads threads(2);
  const auto& x = lattice_1e6();
  const std::vector<float> h(x.size(), 2.0f);
  CellIndex<3, float> ci({.method = Method::CellIndex, .subdivision = static_cast<int>(state.range(0))});
  for (auto _ : state) {
    ci.build(x, h);
    NeighborList nl;
    ci.find_all(nl);
    benchmark::DoNotOptimize(nl.indices.data());
  }
}
BENCHMARK(BM_CellIndexBuildAndFreshLists)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The visitor alone (count neighbours, no list), the loop SPH sums use.
void BM_CellIndexVisitor(benchmark::State& state) {
  ScopedThreads threads(2);
  const auto& x = lattice_1e6();
  const std::vector<float> h(x.size(), 2.0f);
  CellIndex<3, float> ci({.method = Method::CellIndex, .subdivision = static_cast<int>(state.range(0))});
  ci.build(x, h);
  std::vector<std::uint32_t> count(x.size());
  for (auto _ : state) {
    ci.for_each_pair([&](std::uint32_t i, std::uint32_t, float) { ++count[i]; });
    benchmark::DoNotOptimize(count.data());
  }
}
BENCHMARK(BM_CellIndexVisitor)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

std::vector<std::uint64_t> random_keys(std::size_t n, std::uint64_t mask) {
  std::mt19937_64 rng(5);
  std::vector<std::uint64_t> k(n);
  for (auto& v : k) v = rng() & mask;
  return k;
}

// Arg: number of random low bits per key (64: full keys; 38: eq. 17 keys of 10^6 particles).
void BM_RadixSort(benchmark::State& state) {
  ScopedThreads threads(static_cast<int>(state.range(1)));
  const int bits = static_cast<int>(state.range(0));
  const auto keys = random_keys(1000000, bits == 64 ? ~0ull : (1ull << bits) - 1);
  std::vector<std::uint64_t> k, scratch;
  for (auto _ : state) {
    state.PauseTiming();
    k = keys;
    state.ResumeTiming();
    radix_sort(k, scratch);
    benchmark::DoNotOptimize(k.data());
  }
}
BENCHMARK(BM_RadixSort)
    ->Args({64, 1})
    ->Args({64, 2})
    ->Args({38, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

void BM_StdSort(benchmark::State& state) {
  const int bits = static_cast<int>(state.range(0));
  const auto keys = random_keys(1000000, bits == 64 ? ~0ull : (1ull << bits) - 1);
  std::vector<std::uint64_t> k;
  for (auto _ : state) {
    state.PauseTiming();
    k = keys;
    state.ResumeTiming();
    std::sort(k.begin(), k.end());
    benchmark::DoNotOptimize(k.data());
  }
}
BENCHMARK(BM_StdSort)
    ->Arg(64)
    ->Arg(38)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace
}  // namespace cellsph
