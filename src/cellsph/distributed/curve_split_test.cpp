// The curve's cuts on one process, against a brute-force prefix sum over the sorted keys (written here).
#include "cellsph/distributed/curve_split.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

namespace cellsph::distributed {
namespace {

const SumOverRanks kOneProcess = [](std::int64_t*, int) {};

// The weight of the keys below each cut, by brute force, against the cut's share: off by at most the
// tolerance or the weight of one key (a key's particles cannot be split).
void check_balance(const std::vector<std::uint64_t>& keys, const std::vector<std::int64_t>& weights,
                   const CurveSplit& split, double tolerance) {
  std::map<std::uint64_t, std::int64_t> per_key;
  std::int64_t total = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    per_key[keys[i]] += weights[i];
    total += weights[i];
  }
  std::int64_t heaviest_key = 0;
  for (const auto& [k, w] : per_key) heaviest_key = std::max(heaviest_key, w);
  const int ranks = split.ranks();
  const double share = double(total) / ranks;
  for (int r = 1; r < ranks; ++r) {
    ASSERT_LE(split.start[std::size_t(r - 1)], split.start[std::size_t(r)]);
    std::int64_t below = 0;
    for (const auto& [k, w] : per_key)
      if (k < split.start[std::size_t(r)]) below += w;
    EXPECT_LE(std::abs(double(below) - share * r), std::max(tolerance * share, double(heaviest_key)))
        << "cut " << r << " of " << ranks;
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const int o = split.owner(keys[i]);
    ASSERT_GE(o, 0);
    ASSERT_LT(o, ranks);
    EXPECT_GE(keys[i], split.start[std::size_t(o)]);
    EXPECT_LT(keys[i], split.start[std::size_t(o) + 1]);
  }
}

TEST(CurveSplit, UniformKeysEqualShares) {
  std::mt19937_64 rng(7);
  std::vector<std::uint64_t> keys(50000);
  for (auto& k : keys) k = rng() >> 34;  // 30-bit keys
  const std::vector<std::int64_t> w(keys.size(), 1);
  for (const int ranks : {2, 3, 4, 7, 16}) {
    const auto split = split_curve(keys, w, 30, ranks, 0.01, kOneProcess);
    ASSERT_EQ(split.ranks(), ranks);
    EXPECT_EQ(split.start.front(), 0u);
    EXPECT_EQ(split.start.back(), std::uint64_t{1} << 30);
    check_balance(keys, w, split, 0.01);
  }
}

// Most of the work in a sliver of the curve (a splash against a wall), weights from 1 to 60 (row lengths):
// the cuts refine into it.
TEST(CurveSplit, SkewedWeightedKeysRefineIntoTheDenseRange) {
  std::mt19937_64 rng(8);
  std::vector<std::uint64_t> keys(40000);
  std::vector<std::int64_t> w(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    keys[i] = i % 10 == 0 ? rng() >> 1 : (std::uint64_t{1} << 40) + (rng() >> 44);  // 63-bit keys
    w[i] = 1 + static_cast<std::int64_t>(rng() % 60);
  }
  for (const int ranks : {2, 5, 9})
    check_balance(keys, w, split_curve(keys, w, 63, ranks, 0.001, kOneProcess), 0.001);
}

// Few distinct keys: a cut cannot split a key's particles; more ranks than keys leave empty ranges.
TEST(CurveSplit, FewKeysAndMoreRanksThanKeys) {
  const std::vector<std::uint64_t> keys = {5, 5, 5, 9, 9, 100};
  const std::vector<std::int64_t> w = {1, 1, 1, 1, 1, 1};
  const auto split = split_curve(keys, w, 10, 8, 0.0, kOneProcess);
  check_balance(keys, w, split, 0.0);
  const auto none = split_curve({}, {}, 10, 3, 0.1, kOneProcess);
  EXPECT_EQ(none.start, (std::vector<std::uint64_t>{0, 1024, 1024, 1024}));
}

}  // namespace
}  // namespace cellsph::distributed
