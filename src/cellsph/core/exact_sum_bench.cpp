// The cost of an exact global sum (core/exact_sum.hpp) against a plain double sum of the same terms:
// 2^20 terms of random sign over seven decades, in blocks of 1024 as the pass driver sums them.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "cellsph/core/exact_sum.hpp"

namespace {

std::vector<double> sum_terms() {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> x(std::size_t{1} << 20);
  for (double& v : x) v = u(rng) * std::pow(10.0, static_cast<int>(rng() % 7) - 6);
  return x;
}

void BM_PlainSum(benchmark::State& state) {
  const auto x = sum_terms();
  for (auto _ : state) {
    double s = 0;
    for (const double v : x) s += v;
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * x.size()));
}
BENCHMARK(BM_PlainSum);

void BM_ExactSum(benchmark::State& state) {
  const auto x = sum_terms();
  for (auto _ : state) {
    cellsph::ExactSum s;
    for (std::size_t b = 0; b < x.size(); b += 1024)
      s.add_terms(b, b + 1024, [&x](std::size_t i) { return x[i]; });
    benchmark::DoNotOptimize(s.value());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * x.size()));
}
BENCHMARK(BM_ExactSum);

}  // namespace
