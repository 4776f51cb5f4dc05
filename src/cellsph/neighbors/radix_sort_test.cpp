#include "cellsph/neighbors/radix_sort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "cellsph/core/parallel.hpp"

namespace cellsph {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

std::vector<std::uint64_t> random_keys(std::size_t n, std::uint64_t mask, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint64_t> k(n);
  for (auto& v : k) v = rng() & mask;
  return k;
}

// Key sets that stress the pass planner: full range, few bits, all equal, extreme values.
std::vector<std::vector<std::uint64_t>> key_sets(std::size_t n) {
  std::vector<std::vector<std::uint64_t>> sets;
  sets.push_back(random_keys(n, kMax, 11));
  sets.push_back(random_keys(n, 0xFFull, 12));                   // one digit
  sets.push_back(random_keys(n, 0xF0F0'0000'0000'0F00ull, 13));  // sparse varying bits
  sets.push_back(std::vector<std::uint64_t>(n, 42));             // all equal
  sets.push_back(std::vector<std::uint64_t>(n, kMax));           // all max
  auto mix = random_keys(n, kMax, 14);
  for (std::size_t i = 0; i < n; i += 3) mix[i] = kMax;
  for (std::size_t i = 1; i < n; i += 5) mix[i] = 0;
  sets.push_back(mix);
  auto dup = random_keys(n, 0x7ull << 61, 15);  // many duplicates in the top bits only
  sets.push_back(dup);
  return sets;
}

const std::size_t kSizes[] = {0, 1, 2, 3, 17, 1000, 100003};

TEST(RadixSort, MatchesStdSort) {
  for (int threads : {1, 2}) {
    ScopedThreads st(threads);
    for (std::size_t n : kSizes)
      for (const auto& keys : key_sets(n)) {
        auto expect = keys;
        std::sort(expect.begin(), expect.end());
        auto got = keys;
        std::vector<std::uint64_t> scratch;
        radix_sort(got, scratch);
        ASSERT_EQ(got, expect) << "n=" << n << " threads=" << threads;
      }
  }
}

TEST(RadixSort, PairsAreStableLikeStdStableSort) {
  for (int threads : {1, 2}) {
    ScopedThreads st(threads);
    for (std::size_t n : kSizes)
      for (const auto& keys : key_sets(n)) {
        std::vector<std::pair<std::uint64_t, std::uint32_t>> expect(n);
        std::vector<std::uint32_t> payload(n);
        std::mt19937 rng(7);
        for (std::size_t i = 0; i < n; ++i) {
          payload[i] = static_cast<std::uint32_t>(rng());
          expect[i] = {keys[i], payload[i]};
        }
        std::stable_sort(expect.begin(), expect.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        auto k = keys;
        std::vector<std::uint64_t> ks;
        std::vector<std::uint32_t> ps;
        radix_sort_pairs(k, payload, ks, ps);
        ASSERT_EQ(k.size(), n);
        for (std::size_t i = 0; i < n; ++i) {
          ASSERT_EQ(k[i], expect[i].first) << "n=" << n << " i=" << i;
          ASSERT_EQ(payload[i], expect[i].second) << "n=" << n << " i=" << i << " threads=" << threads;
        }
      }
  }
}

TEST(RadixSort, BitRangeSortIsStableOnThoseBitsOnly) {
  // Sorting by bits [8, 40) must equal a stable sort on that field, other bits riding along.
  for (int threads : {1, 2}) {
    ScopedThreads st(threads);
    for (std::size_t n : {std::size_t{0}, std::size_t{5}, std::size_t{50000}}) {
      const auto keys = random_keys(n, kMax, 21);
      const auto field = [](std::uint64_t v) { return (v >> 8) & 0xFFFF'FFFFull; };
      auto expect = keys;
      std::stable_sort(expect.begin(), expect.end(),
                       [&](std::uint64_t a, std::uint64_t b) { return field(a) < field(b); });
      auto got = keys;
      std::vector<std::uint64_t> scratch;
      radix_sort(got, scratch, 8, 40);
      ASSERT_EQ(got, expect) << "n=" << n;
    }
  }
}

TEST(RadixSort, SkipsDigitsWhereAllKeysAgree) {
  // 12 varying bits fit in two digits of at most 11 bits; constant high bits cost nothing.
  auto keys = random_keys(1000, 0xFFFull, 31);
  for (auto& k : keys) k |= 0xABCD'0000'0000'0000ull;
  EXPECT_EQ(radix_sort_passes(keys), 2);
  EXPECT_EQ(radix_sort_passes(std::vector<std::uint64_t>(100, kMax)), 0);
  EXPECT_EQ(radix_sort_passes(random_keys(1000, kMax, 32)), 6);  // 64 bits / 11 -> 6 passes
  EXPECT_EQ(radix_sort_passes(random_keys(1000, kMax, 33), 60, 64), 1);
}

}  // namespace
}  // namespace cellsph
