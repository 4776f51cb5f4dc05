#pragma once
// Cuts a space-filling curve into contiguous ranges of about equal work, one per rank (issue 49 item 2,
// docs/distributed.md): the way of SPH-EXA's Cornerstone, from global histograms of the particles' curve
// keys. Every rank counts the weight (work: neighbour pairs) of its own particles in bins of the key space;
// the counts are summed over the ranks (integers: exact, the same on every rank); the cuts fall where the
// running total crosses each rank's share. A bin that holds a cut and too much weight is split into finer
// bins in the next round, all such bins in one exchange, until every cut is within the tolerance of its
// share or its bin is one key wide. The cuts depend only on the multiset of (key, weight) over all ranks,
// never on which rank holds which particle, so every rank count finds the same cuts from the same particles.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace cellsph::distributed {

// Contiguous ranges of the curve [0, 2^key_bits): rank r owns the keys [start[r], start[r + 1]).
struct CurveSplit {
  std::vector<std::uint64_t> start;  // ranks + 1 entries: 0, ..., 2^key_bits

  int ranks() const { return static_cast<int>(start.size()) - 1; }
  // The rank that owns `key`.
  int owner(std::uint64_t key) const {
    const auto it = std::upper_bound(start.begin(), start.end(), key);
    return static_cast<int>(it - start.begin()) - 1;
  }
};

// Sums integer counts element-wise over the ranks, in place (Communicator::sum_in_place; a no-op on one
// process).
using SumOverRanks = std::function<void(std::int64_t*, int)>;

// The split of the keys (each with its weight, > 0) of every rank's particles into `ranks` ranges, each
// range's weight within `tolerance` (a fraction of the mean share) of its share where the keys allow it.
// Every rank calls it with its own particles and the same other arguments.
inline CurveSplit split_curve(std::span<const std::uint64_t> keys, std::span<const std::int64_t> weights,
                              int key_bits, int ranks, double tolerance, const SumOverRanks& sum) {
  constexpr int kBinBits = 10;  // 1024 bins a histogram
  const std::uint64_t end = key_bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << key_bits);
  CurveSplit split;
  split.start.assign(static_cast<std::size_t>(ranks) + 1, end);
  split.start[0] = 0;
  std::int64_t total = 0;
  for (const std::int64_t w : weights) total += w;
  sum(&total, 1);
  if (ranks <= 1 || total == 0) {
    std::fill(split.start.begin() + 1, split.start.end(), end);
    return split;
  }
  // Each cut's search window: the keys [lo, hi) in which it lies, and the weight below lo.
  struct Window {
    std::uint64_t lo, hi;
    std::int64_t below;
  };
  std::vector<Window> window(static_cast<std::size_t>(ranks) - 1, Window{0, end, 0});
  const double share = double(total) / ranks, slack = tolerance * share;
  std::vector<bool> open(window.size(), true);
  while (std::find(open.begin(), open.end(), true) != open.end()) {
    // The distinct windows of the open cuts (cuts in one bin share it; distinct ones are disjoint), in key
    // order, each with a histogram of 1024 bins (or fewer, one key each); all summed in one exchange.
    std::vector<Window> bins_of;
    for (std::size_t c = 0; c < window.size(); ++c)
      if (open[c]) bins_of.push_back(window[c]);
    std::sort(bins_of.begin(), bins_of.end(), [](const Window& a, const Window& b) { return a.lo < b.lo; });
    bins_of.erase(std::unique(bins_of.begin(), bins_of.end(),
                              [](const Window& a, const Window& b) { return a.lo == b.lo; }),
                  bins_of.end());
    std::vector<std::size_t> first(bins_of.size() + 1, 0);
    std::vector<std::uint64_t> width(bins_of.size(), 1);
    for (std::size_t w = 0; w < bins_of.size(); ++w) {
      const std::uint64_t span = bins_of[w].hi - bins_of[w].lo;
      width[w] = std::max<std::uint64_t>(1, (span >> kBinBits) + ((span & ((1u << kBinBits) - 1)) != 0));
      first[w + 1] = first[w] + static_cast<std::size_t>((span + width[w] - 1) / width[w]);
    }
    std::vector<std::int64_t> hist(first.back(), 0);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const auto it = std::upper_bound(bins_of.begin(), bins_of.end(), keys[i],
                                       [](std::uint64_t k, const Window& w) { return k < w.lo; });
      if (it == bins_of.begin()) continue;
      const auto w = static_cast<std::size_t>(it - bins_of.begin()) - 1;
      if (keys[i] >= bins_of[w].hi) continue;
      hist[first[w] + static_cast<std::size_t>((keys[i] - bins_of[w].lo) / width[w])] += weights[i];
    }
    sum(hist.data(), static_cast<int>(hist.size()));
    for (std::size_t c = 0; c < window.size(); ++c) {
      if (!open[c]) continue;
      const auto w = static_cast<std::size_t>(
          std::lower_bound(bins_of.begin(), bins_of.end(), window[c].lo,
                           [](const Window& a, std::uint64_t k) { return a.lo < k; }) -
          bins_of.begin());
      const double target = share * double(c + 1);
      const std::size_t n = first[w + 1] - first[w];
      std::int64_t below = window[c].below;
      std::size_t b = 0;
      while (b + 1 < n && double(below + hist[first[w] + b]) < target) below += hist[first[w] + b++];
      // Bin b holds the target: cut at whichever of its two edges is nearer, or look inside it.
      const std::uint64_t lo = window[c].lo + b * width[w], hi = std::min(window[c].hi, lo + width[w]);
      const std::int64_t in_bin = hist[first[w] + b];
      const double at_lo = target - double(below), at_hi = double(below + in_bin) - target;
      if (std::min(at_lo, at_hi) <= slack || hi - lo <= 1) {
        split.start[c + 1] = at_lo <= at_hi ? lo : hi;
        open[c] = false;
      } else {
        window[c] = Window{lo, hi, below};
      }
    }
  }
  // Cuts in order (each from its own window: equal targets may give equal cuts, never crossing ones).
  for (std::size_t r = 1; r < split.start.size(); ++r)
    split.start[r] = std::max(split.start[r], split.start[r - 1]);
  return split;
}

}  // namespace cellsph::distributed
