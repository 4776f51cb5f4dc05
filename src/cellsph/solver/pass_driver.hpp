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

#include "cellsph/core/exact_sum.hpp"
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

// The sum of pass(idx[k]) for k < n, exactly, rounded once (core/exact_sum.hpp): the same bits whatever
// the thread count, the order, the split of the entries between threads, a device's blocks or MPI ranks.
// The entries are cut into blocks of kSumBlock for the threads (and the device's block sums), each block
// into its own accumulator, merged at the end. The CUDA driver (cuda/cuda_driver.cuh) accumulates the same
// way, so a device gives the same bits.
inline constexpr std::size_t kSumBlock = 1024;

// Block b's entries (reduce_sum_n's unit) into `acc`.
template <class Pass>
void reduce_sum_block(const std::uint32_t* idx, std::size_t n, std::size_t b, const Pass& pass,
                      ExactSum& acc) {
  // The pass's values first, then their sum: in one loop the accumulator's registers pushed the pass's
  // locals onto the stack (DFSPH's source pass 25% slower, measured).
  double values[kSumBlock];
  const std::size_t begin = b * kSumBlock, count = std::min(n, begin + kSumBlock) - begin;
  for (std::size_t k = 0; k < count; ++k)
    values[k] = static_cast<double>(pass(static_cast<std::size_t>(idx[begin + k])));
  acc.add_terms(0, count, [&values](std::size_t k) { return values[k]; });
}

// The merged value of per-block accumulators.
inline double merged_value(const std::vector<ExactSum>& partial) {
  ExactSum s;
  for (const ExactSum& q : partial) s.merge(q);
  return s.value();
}

// The same sum before its rounding: the accumulator, for a sum over MPI ranks (Communicator::sum).
template <class Pass>
ExactSum reduce_sum_exact_n(const std::uint32_t* idx, std::size_t n, const Pass& pass) {
  const std::size_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<ExactSum> partial(blocks);
  parallel_for(blocks, [&](std::size_t b) { reduce_sum_block(idx, n, b, pass, partial[b]); });
  ExactSum s;
  for (const ExactSum& q : partial) s.merge(q);
  return s;
}

template <class Pass>
double reduce_sum_n(const std::uint32_t* idx, std::size_t n, const Pass& pass) {
  return reduce_sum_exact_n(idx, n, pass).value();
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

// An index set split between the threads by weight instead of by count: part t, entries [cuts[t],
// cuts[t + 1]), runs on thread t in every pass (as the static split keeps a thread on the same particles
// from pass to pass). The solver weighs a particle by its row length, so that each thread walks about as
// many pairs: split by count, the first thread of the DFSPH dam break walked 4% more pairs than the second
// (a dynamic schedule was slower, docs/benchmarks.md). reduce_sum splits the same way in whole blocks
// (block_cuts), so a sum adds the same blocks in the same order: the split moves no result, only time. A
// team of another size than the split's runs the parts round robin.
struct BalancedIndexSet {
  const IndexSet* set = nullptr;
  std::vector<std::size_t> cuts;        // run_pass: parts + 1 entries, 0, ..., set->size()
  std::vector<std::size_t> block_cuts;  // reduce_sum: the same in reduce_sum's blocks, 0, ..., blocks
};

// The split of `set` into `parts` by weight(i) for each index i (give a particle with an empty row some
// weight too: its own loads and stores take time): each inner cut is the entry where its share of the
// total weight is reached, and for reduce_sum the block boundary nearest to it (or equal numbers of
// blocks, where that is better balanced).
template <class Weight>
void balance(const IndexSet& set, std::size_t parts, const Weight& weight, BalancedIndexSet& out) {
  const std::size_t n = set.size(), blocks = (n + kSumBlock - 1) / kSumBlock;
  parts = std::max<std::size_t>(parts, 1);
  std::vector<std::uint64_t> before(blocks + 1, 0);  // the weight of the blocks ahead of each boundary
  parallel_for(blocks, [&](std::size_t b) {
    std::uint64_t w = 0;
    for (std::size_t k = b * kSumBlock; k < std::min(n, (b + 1) * kSumBlock); ++k) w += weight(set[k]);
    before[b + 1] = w;
  });
  for (std::size_t b = 0; b < blocks; ++b) before[b + 1] += before[b];
  out.set = &set;
  out.cuts.assign(parts + 1, n);
  out.block_cuts.assign(parts + 1, blocks);
  out.cuts[0] = out.block_cuts[0] = 0;
  for (std::size_t t = 1; t < parts; ++t) {
    const double share = double(before[blocks]) * double(t) / double(parts);
    // The first boundary at or past the share, and the entry within the block before it.
    std::size_t b =
        static_cast<std::size_t>(std::lower_bound(before.begin(), before.end(), share) - before.begin());
    b = std::min(b, blocks);
    std::size_t k = b > 0 ? (b - 1) * kSumBlock : 0;
    for (std::uint64_t w = b > 0 ? before[b - 1] : 0; k < std::min(n, b * kSumBlock) && double(w) < share;
         ++k)
      w += weight(set[k]);
    out.cuts[t] = std::max(k, out.cuts[t - 1]);
    if (b > 0 && share - double(before[b - 1]) < double(before[b]) - share) --b;
    out.block_cuts[t] = std::max(b, out.block_cuts[t - 1]);
  }
  // With few blocks a part, rounding to blocks can leave a part heavier than the static split's (blocks in
  // equal numbers, reduce_sum_n's): keep whichever has the lighter heaviest part.
  std::vector<std::size_t> by_count(parts + 1);
  for (std::size_t t = 0; t <= parts; ++t) by_count[t] = blocks * t / parts;
  auto heaviest = [&](const std::vector<std::size_t>& c) {
    std::uint64_t m = 0;
    for (std::size_t t = 0; t < parts; ++t) m = std::max(m, before[c[t + 1]] - before[c[t]]);
    return m;
  };
  if (heaviest(by_count) < heaviest(out.block_cuts)) out.block_cuts = by_count;
}

// f(part) for every part of a balanced set, part t on thread t where the team has the split's size.
template <class F>
void for_each_part(const BalancedIndexSet& set, F&& f) {
  const auto parts = static_cast<std::int64_t>(set.cuts.size() - 1);
#pragma omp parallel
  {
    const auto nt = static_cast<std::int64_t>(omp_get_num_threads());
    for (auto t = static_cast<std::int64_t>(omp_get_thread_num()); t < parts; t += nt)
      f(static_cast<std::size_t>(t));
  }
}

template <class Pass>
void run_pass(const BalancedIndexSet& set, const Pass& pass) {
  const std::uint32_t* idx = set.set->data();
  for_each_part(set, [&](std::size_t t) {
    for (std::size_t k = set.cuts[t]; k < set.cuts[t + 1]; ++k) pass(static_cast<std::size_t>(idx[k]));
  });
}

// reduce_sum_n's blocks, each part summing its blocks (block_cuts): the exact sum, as for the plain set.
template <class Pass>
double reduce_sum(const BalancedIndexSet& set, const Pass& pass) {
  const std::uint32_t* idx = set.set->data();
  const std::size_t n = set.set->size();
  std::vector<ExactSum> partial((n + kSumBlock - 1) / kSumBlock);
  for_each_part(set, [&](std::size_t t) {
    for (std::size_t b = set.block_cuts[t]; b < set.block_cuts[t + 1]; ++b)
      reduce_sum_block(idx, n, b, pass, partial[b]);
  });
  return merged_value(partial);
}

inline std::size_t set_size(const BalancedIndexSet& set) {
  return set.set->size();
}

// A maximum does not depend on the split: the plain set's.
template <class Result, class Pass>
Result reduce_max(const BalancedIndexSet& set, Result init, const Pass& pass) {
  return reduce_max(*set.set, init, pass);
}

}  // namespace cellsph
