// The pass driver against sequential loops (every index once, maxima, first matches, for several thread
// counts), and passes run on a hand-made ParticleView against values written out by hand: a pass needs
// nothing but the view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/models/summation_density.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/stability_check.hpp"
#include "cellsph/solver/verlet_rows.hpp"

namespace cellsph {
namespace {

struct MaxPair {
  double a = 0, b = 0;
  static MaxPair max_of(const MaxPair& x, const MaxPair& y) {
    return {std::max(x.a, y.a), std::max(x.b, y.b)};
  }
};

IndexSet random_set(std::mt19937& rng, std::uint32_t n) {
  IndexSet set;
  for (std::uint32_t i = 0; i < n; ++i)
    if (rng() % 3 != 0) set.push_back(i);
  return set;
}

TEST(PassDriver, RunPassVisitsEveryIndexOfTheSetOnce) {
  std::mt19937 rng(7);
  for (const int threads : {1, 2, 3}) {
    ScopedThreads st(threads);
    const IndexSet set = random_set(rng, 1001);
    std::vector<int> hits(1001, 0);
    run_pass(set, [&](std::size_t i) { ++hits[i]; });  // each i written by one thread only
    for (std::uint32_t i = 0; i < 1001; ++i)
      EXPECT_EQ(hits[i], std::count(set.begin(), set.end(), i) ? 1 : 0) << i;
    std::vector<int> all(37, 0);
    run_pass(all.size(), [&](std::size_t i) { all[i] += 2; });
    EXPECT_EQ(std::count(all.begin(), all.end(), 2), 37);
  }
}

TEST(PassDriver, ReduceMaxAndFirstWhereMatchSequentialLoops) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const int threads : {1, 2, 3, 5}) {
    ScopedThreads st(threads);
    for (int trial = 0; trial < 20; ++trial) {
      const IndexSet set = random_set(rng, 500);
      std::vector<double> va(500), vb(500);
      for (auto& x : va) x = u(rng);
      for (auto& x : vb) x = u(rng);
      MaxPair want;
      for (const auto i : set) want = {std::max(want.a, va[i]), std::max(want.b, vb[i])};
      const MaxPair got = reduce_max(set, MaxPair{}, [&](std::size_t i) { return MaxPair{va[i], vb[i]}; });
      EXPECT_EQ(got.a, want.a);
      EXPECT_EQ(got.b, want.b);

      const double cut = trial == 0 ? 2.0 : 0.9;  // trial 0: no index qualifies
      std::int64_t first = -1;
      for (const auto i : set)
        if (va[i] > cut) {
          first = i;
          break;
        }
      EXPECT_EQ(first_where(set, [&](std::size_t i) { return va[i] > cut; }), first);
    }
  }
  EXPECT_EQ(first_where(IndexSet{}, [](std::size_t) { return true; }), -1);
  EXPECT_EQ(reduce_max(IndexSet{}, MaxPair{-1, -2}, [](std::size_t) { return MaxPair{5, 5}; }).b, -2);
}

// Three particles on the x axis at 0, 0.3 and 0.9 with h = 1, 1 and 0.5: the candidate rows hold every
// pair; within h_i: 0 -> {1, 2}, 1 -> {0, 2}, 2 -> {} (0.9 and 0.6 away, beyond its 0.5).
struct Line {
  std::vector<Vec<2, double>> x{Vec<2, double>{{0.0, 0.0}}, Vec<2, double>{{0.3, 0.0}},
                                Vec<2, double>{{0.9, 0.0}}};
  std::vector<double> m{1.0, 2.0, 4.0}, h{1.0, 1.0, 0.5}, rho{0, 0, 0}, p{0, 0, 0}, vol{0, 0, 0},
      prho2{0, 0, 0};
  std::vector<double> rho0{1000, 1000, 1000};
  std::vector<std::uint8_t> kind{0, 0, 0};
  std::vector<std::uint64_t> offsets{0, 2, 4, 6};
  std::vector<std::uint32_t> candidates{1, 2, 0, 2, 0, 1}, within{9, 9, 9, 9, 9, 9}, count{0, 0, 0};
  ParticleView<2, double> view() {
    ParticleView<2, double> v;
    v.n = 3;
    v.x = x.data();
    v.m = m.data();
    v.h = h.data();
    v.rho = rho.data();
    v.p = p.data();
    v.vol = vol.data();
    v.prho2 = prho2.data();
    v.rho0 = rho0.data();
    v.kind = kind.data();
    v.offsets = offsets.data();
    v.candidates = candidates.data();
    v.within = within.data();
    v.within_count = count.data();
    return v;
  }
};

// The exact sum rounded once, for every thread count: values m 2^e (m < 2^53, e in [-60, 0]) whose exact sum
// a 128-bit integer in units of 2^-60 holds, converted to double by the compiler's correctly rounded
// conversion (the reference, apart from core/exact_sum.hpp).
TEST(PassDriver, ReduceSumIsTheExactSumRoundedOnceWhateverTheThreadCount) {
  __extension__ typedef __int128 Int128;
  std::mt19937_64 rng(11);
  std::vector<double> value(5000);
  std::vector<Int128> units(5000);
  for (std::size_t i = 0; i < value.size(); ++i) {
    const auto m = static_cast<std::int64_t>(rng() >> 11);
    const int e = static_cast<int>(rng() % 61) - 60;
    const bool negative = (rng() & 1) != 0;
    value[i] = std::ldexp(static_cast<double>(m), e) * (negative ? -1 : 1);
    units[i] = (static_cast<Int128>(m) << (e + 60)) * (negative ? -1 : 1);
  }
  std::mt19937 rng32(11);
  const IndexSet set = random_set(rng32, 5000);  // about 3300 entries: four blocks, the last partial
  auto pass = [&](std::size_t i) { return value[i]; };
  Int128 total = 0;
  for (const std::uint32_t i : set) total += units[i];
  const double want = std::ldexp(static_cast<double>(total), -60);
  for (const int threads : {1, 2, 3}) {
    ScopedThreads st(threads);
    EXPECT_EQ(reduce_sum(set, pass), want) << threads << " threads";
  }
  EXPECT_EQ(reduce_sum(IndexSet{}, pass), 0.0);
}

// A set split by weight: every index once, the cuts on block boundaries and near each part's share of
// the weight, sums with the plain set's bits, for splits into as many parts as threads and into others.
TEST(PassDriver, BalancedSetSplitsByWeightAndKeepsEverySum) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> value(200000);
  for (double& v : value) v = u(rng) * std::pow(10.0, static_cast<int>(rng() % 9) - 4);
  const IndexSet set = random_set(rng, 200000);  // about 133 000 entries, 131 blocks
  // Heavy rows in the first quarter of the set: a split by count would give the first part most weight.
  // Weights of 1-60 in the first quarter, 1-10 after it: half the weight lies in the first fifth.
  std::vector<std::uint64_t> weight(200000);
  for (std::uint32_t i = 0; i < 200000; ++i) weight[i] = 1 + (i < 50000 ? rng() % 60 : rng() % 10);
  auto pass = [&](std::size_t i) { return value[i]; };
  for (const int threads : {1, 2, 3}) {
    ScopedThreads st(threads);
    const double want = reduce_sum(set, pass);
    for (const std::size_t parts : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{4}}) {
      BalancedIndexSet split;
      balance(
          set, parts, [&](std::uint32_t i) { return weight[i]; }, split);
      ASSERT_EQ(split.cuts.size(), parts + 1);
      ASSERT_EQ(split.block_cuts.size(), parts + 1);
      EXPECT_EQ(split.cuts.front(), 0u);
      EXPECT_EQ(split.cuts.back(), set.size());
      EXPECT_EQ(split.block_cuts.front(), 0u);
      EXPECT_EQ(split.block_cuts.back(), (set.size() + kSumBlock - 1) / kSumBlock);
      std::uint64_t total = 0, heaviest = 0;  // the set's weight, and its heaviest entry's and block's
      std::uint64_t heaviest_entry = 0;
      for (std::size_t k0 = 0; k0 < set.size(); k0 += kSumBlock) {
        std::uint64_t w = 0;
        for (std::size_t k = k0; k < std::min(set.size(), k0 + kSumBlock); ++k) {
          w += weight[set[k]];
          heaviest_entry = std::max(heaviest_entry, weight[set[k]]);
        }
        total += w;
        heaviest = std::max(heaviest, w);
      }
      for (std::size_t t = 1; t < parts; ++t) {
        EXPECT_GE(split.cuts[t], split.cuts[t - 1]);
        EXPECT_GE(split.block_cuts[t], split.block_cuts[t - 1]);
        std::uint64_t before = 0, before_block = 0;
        for (std::size_t k = 0; k < split.cuts[t]; ++k) before += weight[set[k]];
        for (std::size_t k = 0; k < std::min(set.size(), split.block_cuts[t] * kSumBlock); ++k)
          before_block += weight[set[k]];
        // The entry cut within one entry's weight of its share, the block cut within half a block's.
        const double share = double(total) * double(t) / double(parts);
        EXPECT_NEAR(double(before), share, double(heaviest_entry)) << parts << " parts, cut " << t;
        if (parts <= 4) {  // 33 or more blocks a part: the block cuts are the weighted ones
          EXPECT_NEAR(double(before_block), share, 0.5 * double(heaviest)) << parts << " parts, cut " << t;
        }
      }
      if (parts == 2) {
        EXPECT_LT(split.cuts[1], set.size() / 4) << "the heavy first quarter moves the cut down";
      }
      std::vector<int> hits(200000, 0);
      run_pass(split, [&](std::size_t i) { ++hits[i]; });
      for (const std::uint32_t i : set) EXPECT_EQ(hits[i], 1) << i;
      EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), static_cast<std::ptrdiff_t>(set.size()));
      EXPECT_EQ(reduce_sum(split, pass), want) << threads << " threads, " << parts << " parts";
      EXPECT_EQ(set_size(split), set.size());
      double mx = 0;
      for (const std::uint32_t i : set) mx = std::max(mx, value[i]);
      EXPECT_EQ(reduce_max(split, MaxPair{}, [&](std::size_t i) { return MaxPair{value[i], 0}; }).a, mx);
    }
  }
  // Sets of one partial block and a little more, split in more parts than blocks: every entry once in a
  // sum too (a pass may write as it sums).
  for (const std::uint32_t n : {700u, 1500u}) {
    const IndexSet small = random_set(rng, n);
    for (const int threads : {1, 2, 3}) {
      ScopedThreads st(threads);
      for (const std::size_t parts : {std::size_t{2}, std::size_t{3}}) {
        BalancedIndexSet split;
        balance(
            small, parts, [&](std::uint32_t i) { return weight[i]; }, split);
        std::vector<int> hits(n, 0);
        const double visits = reduce_sum(split, [&](std::size_t i) { return double(++hits[i]); });
        EXPECT_EQ(visits, double(small.size()))
            << n << " entries, " << threads << " threads, " << parts << " parts";
        for (const std::uint32_t i : small) EXPECT_EQ(hits[i], 1) << i;
      }
    }
  }
  BalancedIndexSet empty_split;
  const IndexSet empty;
  balance(
      empty, 2, [](std::uint32_t) { return std::uint64_t{1}; }, empty_split);
  EXPECT_EQ(reduce_sum(empty_split, pass), 0.0);
  run_pass(empty_split, [](std::size_t) { ADD_FAILURE() << "a pass over an empty set"; });
}

// Rows searched at h itself are used as they are: only their lengths are written.
TEST(Passes, RowLengthPassCountsRowsAsTheyAre) {
  Line l;
  run_pass(IndexSet{0, 1, 2}, RowLengthPass<2, double>{l.view()});
  EXPECT_EQ(l.count, (std::vector<std::uint32_t>{2, 2, 2}));
}

TEST(Passes, FilterRowsAndSummationDensityOnAHandMadeView) {
  Line l;
  const IndexSet all{0, 1, 2};
  run_pass(all, FilterRowsPass<2, double>{l.view(), l.within.data()});
  EXPECT_EQ(l.count, (std::vector<std::uint32_t>{2, 2, 0}));
  EXPECT_EQ(l.within[0], 1u);
  EXPECT_EQ(l.within[1], 2u);
  EXPECT_EQ(l.within[2], 0u);
  EXPECT_EQ(l.within[3], 2u);

  EquationOfState<double> eos;
  eos.kind = EosKind::Linear;
  eos.stiffness = 10;
  const Poly6Kernel<2, double> w(1.0);  // the pass's kernel support; rows decide who counts
  run_pass(all, SummationDensityPass<2, double, Poly6Kernel<2, double>>{l.view(), w, eos, false});
  const double rho0 = 1 * w.W2(0) + 2 * w.W2(0.09) + 4 * w.W2(0.81);
  const double rho1 = 2 * w.W2(0) + 1 * w.W2(0.09) + 4 * w.W2(0.36);
  const double rho2 = 4 * w.W2(0);
  EXPECT_NEAR(l.rho[0], rho0, 1e-12 * rho0);
  EXPECT_NEAR(l.rho[1], rho1, 1e-12 * rho1);
  EXPECT_NEAR(l.rho[2], rho2, 1e-12 * rho2);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(l.p[i], 10 * (l.rho[i] - 1000), 1e-9 * std::abs(l.p[i]) + 1e-9);
    EXPECT_DOUBLE_EQ(l.vol[i], l.m[i] / l.rho[i]);
  }
}

TEST(Passes, StabilityCheckFindsTheFirstBadParticle) {
  Line l;
  l.rho = {1, 1, 1};
  std::vector<Vec<2, double>> v(3), f(3);
  auto pv = l.view();
  pv.v = v.data();
  pv.f = f.data();
  const IndexSet all{0, 1, 2};
  const StabilityCheckPass<2, double> inside{pv, true, Vec<2, double>{{0.0, 0.0}}, Vec<2, double>{{1.0, 1.0}},
                                             0.05};
  EXPECT_EQ(first_where(all, inside), -1);
  l.x[2][0] = 1.2;  // beyond hi + margin
  l.p[1] = std::nan("");
  EXPECT_EQ(first_where(all, inside), 1);
  l.p[1] = 0;
  EXPECT_EQ(first_where(all, inside), 2);
  const StabilityCheckPass<2, double> no_domain{pv, false, Vec<2, double>{{0.0, 0.0}},
                                                Vec<2, double>{{1.0, 1.0}}, 0.05};
  EXPECT_EQ(first_where(all, no_domain), -1);
  // A speed or an acceleration whose square overflows (the Courant step would be 0), finite as it is.
  v[0] = Vec<2, double>{{1e150, 0.0}};
  f[2] = Vec<2, double>{{0.0, 4e150}};  // m = 4: |a|^2 = 1e300
  EXPECT_EQ(first_where(all, no_domain), -1);
  f[2] = Vec<2, double>{{0.0, 1e110}};
  l.m[2] = 1e-100;  // |f|^2 = 1e220 is finite, |a|^2 = 1e420 is not
  EXPECT_EQ(first_where(all, no_domain), 2);
  v[0] = Vec<2, double>{{1e160, 0.0}};
  EXPECT_EQ(first_where(all, no_domain), 0);
}

}  // namespace
}  // namespace cellsph
