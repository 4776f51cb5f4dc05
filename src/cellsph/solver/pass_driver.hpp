#pragma once
// The driver that runs a per-particle pass (a functor pass(i) over a ParticleView, particle_view.hpp)
// over a set of particle indices. On the CPU: an OpenMP loop, statically scheduled over the set, so
// the split (and with it every result) depends only on the thread count. Every pass writes only
// particle i's own entries (or reduces), so the order in which the indices run does not matter.
//
// The device backends (solver/device/) overload run_pass, reduce_max and first_where for their index
// sets (DeviceIndexSet<Space>): the model files call them unchanged, and with a CUDA index set they are
// kernel launches over the same passes (cuda/cuda_driver.cuh).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "cellsph/core/parallel.hpp"

namespace cellsph {

using IndexSet = std::vector<std::uint32_t>;

// pass(i) for every i in `set` (ascending indices, usually).
template <class Pass>
void run_pass(const IndexSet& set, const Pass& pass) {
  const std::uint32_t* idx = set.data();
  parallel_for(set.size(), [&](std::size_t k) { pass(static_cast<std::size_t>(idx[k])); });
}

// pass(i) for every i in [0, n).
template <class Pass>
void run_pass(std::size_t n, const Pass& pass) {
  parallel_for(n, [&](std::size_t i) { pass(i); });
}

// The largest pass(idx[k]) over k in [0, count), each value a Result with members combined by
// Result::max_of (a maximum does not depend on the order of evaluation, so the reduction is
// deterministic). Starts from `init`. The index array is host memory (the CPU, or the host-emulated
// device of solver/device/).
template <class Result, class Pass>
Result reduce_max_n(const std::uint32_t* idx, std::size_t n, Result init, const Pass& pass) {
  std::vector<Result> partial(static_cast<std::size_t>(max_threads()), init);
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel
  {
    Result r = init;
#pragma omp for schedule(static) nowait
    for (std::int64_t k = 0; k < count; ++k) r = Result::max_of(r, pass(static_cast<std::size_t>(idx[k])));
    partial[static_cast<std::size_t>(thread_id())] = r;
  }
  Result r = init;
  for (const Result& q : partial) r = Result::max_of(r, q);
  return r;
}

// The sum of pass(idx[k]) for k < n, in double, independent of the thread count: the entries are cut into
// fixed blocks of kSumBlock, each summed in order, and the block sums are added in order (a plain
// per-thread partial sum would change in the last bits with the thread count). The CUDA driver
// (cuda/cuda_driver.cuh) adds in the same order, so a device gives the same bits.
inline constexpr std::size_t kSumBlock = 1024;

template <class Pass>
double reduce_sum_n(const std::uint32_t* idx, std::size_t n, const Pass& pass) {
  const std::size_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<double> partial(blocks, 0.0);
  parallel_for(blocks, [&](std::size_t b) {
    double s = 0;
    const std::size_t end = std::min(n, (b + 1) * kSumBlock);
    for (std::size_t k = b * kSumBlock; k < end; ++k)
      s += static_cast<double>(pass(static_cast<std::size_t>(idx[k])));
    partial[b] = s;
  });
  double s = 0;
  for (const double q : partial) s += q;
  return s;
}

// The number of indices of a set (a device set, device_driver.hpp, has its own overload).
inline std::size_t set_size(const IndexSet& set) {
  return set.size();
}

template <class Pass>
double reduce_sum(const IndexSet& set, const Pass& pass) {
  return reduce_sum_n(set.data(), set.size(), pass);
}

// The lowest index idx[k] with pred(idx[k]) true, or -1 if none (deterministic: a minimum).
template <class Pred>
std::int64_t first_where_n(const std::uint32_t* idx, std::size_t n, const Pred& pred) {
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) reduction(min : first)
  for (std::int64_t k = 0; k < count; ++k) {
    const std::uint32_t i = idx[k];
    if (pred(static_cast<std::size_t>(i))) first = std::min(first, static_cast<std::int64_t>(i));
  }
  return first == std::numeric_limits<std::int64_t>::max() ? -1 : first;
}

// The largest pass(i) over `set` (reduce_max_n).
template <class Result, class Pass>
Result reduce_max(const IndexSet& set, Result init, const Pass& pass) {
  return reduce_max_n(set.data(), set.size(), init, pass);
}

// The lowest index i of `set` with pred(i) true, or -1 if none.
template <class Pred>
std::int64_t first_where(const IndexSet& set, const Pred& pred) {
  return first_where_n(set.data(), set.size(), pred);
}

}  // namespace cellsph
