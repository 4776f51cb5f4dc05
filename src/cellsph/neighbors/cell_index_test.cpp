// Cell Indexing against the all-pairs reference: exact CSR equality on point sets chosen to break
// cell arithmetic (points on cell faces, far offsets, duplicates, variable h, both key layouts).
#include "cellsph/neighbors/cell_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/neighbors/point_sets.hpp"

namespace cellsph {
namespace {

template <int Dim, class Real>
using Points = std::vector<Vec<Dim, Real>>;

template <int Dim, class Real>
NeighborList all_pairs(const Points<Dim, Real>& x, const std::vector<Real>& h) {
  NeighborSearch<Dim, Real> ns({.method = Method::AllPairs});
  ns.build(x, h);
  NeighborList nl;
  ns.find_all(nl);
  return nl;
}

// Checks the visitor contract: every call for one i on one thread, consecutively, and r2 equal to
// distance2 bit for bit. Returns the lists built from the visitor (rows sorted).
template <int Dim, class Real>
NeighborList via_visitor(const CellIndex<Dim, Real>& ci, const Points<Dim, Real>& x) {
  const std::size_t n = x.size();
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> per_thread(
      static_cast<std::size_t>(max_threads()));
  bool r2_exact = true;
  ci.for_each_pair([&](std::uint32_t i, std::uint32_t j, Real r2) {
    per_thread[static_cast<std::size_t>(thread_id())].push_back({i, j});
    if (r2 != distance2(x[i], x[j])) r2_exact = false;  // races only ever write false
  });
  EXPECT_TRUE(r2_exact);
  std::vector<int> owner(n, -1);
  std::vector<std::vector<std::uint32_t>> rows(n);
  for (std::size_t t = 0; t < per_thread.size(); ++t) {
    std::uint32_t last = 0;
    bool any = false;
    for (auto [i, j] : per_thread[t]) {
      if (!any || i != last) {
        EXPECT_EQ(owner[i], -1) << "calls for i=" << i << " are not consecutive on one thread";
        owner[i] = static_cast<int>(t);
      }
      any = true;
      last = i;
      rows[i].push_back(j);
    }
  }
  NeighborList nl;
  nl.offsets.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(rows[i].begin(), rows[i].end());
    nl.offsets[i + 1] = nl.offsets[i] + rows[i].size();
    nl.indices.insert(nl.indices.end(), rows[i].begin(), rows[i].end());
  }
  return nl;
}

// Cell Indexing equals all-pairs for H = 1..3, both key layouts, 1 and 2 threads, through
// find_all (own CSR builder), the generic builder over the visitor, and NeighborSearch.
template <int Dim, class Real>
void expect_exact(const Points<Dim, Real>& x, const std::vector<Real>& h, const std::string& what) {
  const NeighborList ref = all_pairs<Dim, Real>(x, h);
  for (int H : {1, 2, 3})
    for (bool wide : {false, true}) {
      FreshVector<std::uint32_t> unsorted_one_thread;
      for (int threads : {1, 2}) {
        SCOPED_TRACE(what + " H=" + std::to_string(H) + (wide ? " wide" : " packed") +
                     " threads=" + std::to_string(threads));
        ScopedThreads st(threads);
        CellIndex<Dim, Real> ci({.method = Method::CellIndex, .subdivision = H});
        ci.force_wide_keys(wide);
        ci.build(x, h);
        EXPECT_EQ(ci.wide_keys(), wide);
        NeighborList a;
        const std::uint64_t cand = ci.find_all(a);
        EXPECT_EQ(a.offsets, ref.offsets);
        EXPECT_EQ(a.indices, ref.indices);
        EXPECT_GE(cand, a.pairs());
        // The count-only traversal: every row's length, the same pairs in all.
        std::vector<std::uint64_t> counts;
        EXPECT_EQ(ci.count_pairs(counts), ref.pairs());
        ASSERT_EQ(counts.size(), x.size());
        for (std::size_t i = 0; i < x.size(); ++i)
          ASSERT_EQ(counts[i], ref.offsets[i + 1] - ref.offsets[i]) << i;
        NeighborList b;
        EXPECT_EQ(build_csr(ci, x.size(), b), cand);
        EXPECT_EQ(b.indices, ref.indices);
        const NeighborList c = via_visitor(ci, x);
        EXPECT_EQ(c.offsets, ref.offsets);
        EXPECT_EQ(c.indices, ref.indices);
        if (!wide) {
          NeighborSearch<Dim, Real> ns({.method = Method::CellIndex, .subdivision = H});
          ns.build(x, h);
          NeighborList d;
          ns.find_all(d);
          EXPECT_EQ(d.indices, ref.indices);
          EXPECT_EQ(ns.stats().candidates, cand);
        }
        // Rows left in the search's order: the same sets, and the same bits for 1 and 2 threads.
        CellIndex<Dim, Real> cu({.method = Method::CellIndex, .subdivision = H, .sorted_rows = false});
        cu.force_wide_keys(wide);
        cu.build(x, h);
        NeighborList e;
        cu.find_all(e);
        EXPECT_EQ(e.offsets, ref.offsets);
        if (threads == 1)
          unsorted_one_thread = e.indices;
        else
          EXPECT_EQ(e.indices, unsorted_one_thread);
        for (std::size_t i = 0; i + 1 < e.offsets.size(); ++i)
          std::sort(e.indices.begin() + static_cast<std::ptrdiff_t>(e.offsets[i]),
                    e.indices.begin() + static_cast<std::ptrdiff_t>(e.offsets[i + 1]));
        EXPECT_EQ(e.indices, ref.indices);
      }
    }
}

template <int Dim, class Real>
std::vector<Real> constant_h(std::size_t n, double r) {
  return std::vector<Real>(n, static_cast<Real>(r));
}

// Support lengths spread over a 10x range [0.25 r, 2.5 r].
template <class Real>
std::vector<Real> variable_h(std::size_t n, double r, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.25, 2.5);
  std::vector<Real> h(n);
  for (auto& v : h) v = static_cast<Real>(r * u(rng));
  return h;
}

template <int Dim, class Real>
void run_point_sets() {
  {
    const auto x = point_sets::uniform_random<Dim, Real>(1200, Real(1));
    expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 1.5), "uniform r=1.5");
    expect_exact<Dim, Real>(x, variable_h<Real>(x.size(), 1.0, 5), "uniform variable h");
  }
  {
    const auto x = point_sets::clustered<Dim, Real>(1000, Real(1), 3);
    expect_exact<Dim, Real>(x, variable_h<Real>(x.size(), 0.7, 6), "clustered variable h");
  }
  {
    // Lattice of spacing 1 with h = 1 and 2: many pairs at distance exactly h.
    const auto x = point_sets::jittered_lattice<Dim, Real>(Dim == 2 ? 900 : 1000, Real(1), Real(0));
    expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 1.0), "lattice h=1");
    expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 2.0), "lattice h=2");
  }
  {
    // Points exactly on the faces of the H = 1 and H = 2 cells (multiples of the cell size).
    for (int H : {1, 2}) {
      const double r = 1.0;
      const double c = r / H * kCellInflation;
      auto x = point_sets::jittered_lattice<Dim, Real>(Dim == 2 ? 400 : 512, Real(1), Real(0));
      for (auto& p : x)
        for (int k = 0; k < Dim; ++k) p[k] = static_cast<Real>(double(p[k]) * c);
      expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), r), "cell faces H=" + std::to_string(H));
    }
  }
  {
    // Negative and far-off coordinates (1e6 offset), float rounding included.
    for (double off : {-1.0e6, 1.0e6, -37.5}) {
      auto x = point_sets::uniform_random<Dim, Real>(800, Real(1));
      for (auto& p : x)
        for (int k = 0; k < Dim; ++k) p[k] = static_cast<Real>(double(p[k]) + off);
      expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 1.3), "offset " + std::to_string(off));
    }
  }
  {
    // Duplicates: every point three times (distance 0 pairs, equal keys but for the index).
    auto x = point_sets::uniform_random<Dim, Real>(300, Real(1));
    const auto base = x;
    x.insert(x.end(), base.begin(), base.end());
    x.insert(x.end(), base.begin(), base.end());
    expect_exact<Dim, Real>(x, variable_h<Real>(x.size(), 1.0, 7), "duplicates");
  }
  {
    // All points in one cell.
    auto x = point_sets::uniform_random<Dim, Real>(200, Real(0.001));
    expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 10.0), "one cell");
  }
  {
    Points<Dim, Real> one(1);
    one[0][0] = Real(3);
    expect_exact<Dim, Real>(one, constant_h<Dim, Real>(1, 1.0), "one point");
    expect_exact<Dim, Real>(Points<Dim, Real>{}, std::vector<Real>{}, "no points");
    // Zero support: only exact duplicates are neighbours.
    auto x = point_sets::jittered_lattice<Dim, Real>(16, Real(1), Real(0));
    x.push_back(x[3]);
    expect_exact<Dim, Real>(x, constant_h<Dim, Real>(x.size(), 0.0), "h = 0");
  }
}

TEST(CellIndex, MatchesAllPairs2DFloat) {
  run_point_sets<2, float>();
}
TEST(CellIndex, MatchesAllPairs2DDouble) {
  run_point_sets<2, double>();
}
TEST(CellIndex, MatchesAllPairs3DFloat) {
  run_point_sets<3, float>();
}
TEST(CellIndex, MatchesAllPairs3DDouble) {
  run_point_sets<3, double>();
}

// `centres` random points in the box [0, box) and, around each, one point at distance h (1 + rel) per
// rel, in a random direction: pairs whose distance2 falls within a few ulps (or more) of h^2.
Points<3, double> pairs_near_the_support(std::uint64_t seed, int centres, const Vec<3, double>& box, double h,
                                         std::initializer_list<double> rels) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points<3, double> x;
  for (int c = 0; c < centres; ++c) {
    const Vec<3, double> o{{box[0] * u(rng), box[1] * u(rng), box[2] * u(rng)}};
    x.push_back(o);
    for (double rel : rels) {
      // A random direction, then the distance nudged until distance2 falls where we want it.
      Vec<3, double> d{{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int k = 0; k < 3; ++k) d[k] *= h * (1 + rel) / len;
      x.push_back({{o[0] + d[0], o[1] + d[1], o[2] + d[2]}});
    }
  }
  return x;
}

// Pairs whose distance differs from h by less than float could resolve (a few ulps of double up to
// 1e-6 h), in a box 300 h wide: the float test and its re-test in double must decide each as
// distance2 does.
TEST(CellIndex, PairsWithinUlpsOfTheSupportMatchAllPairs) {
  const double h = 0.37;
  const Points<3, double> x = pairs_near_the_support(
      17, 200, {{300 * h, 300 * h, 300 * h}}, h, {-1e-6, -1e-7, -3e-8, -1e-15, 0.0, 1e-15, 3e-8, 1e-7, 1e-6});
  std::size_t near = 0;  // pairs within float's resolution of the support
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < x.size(); ++j)
      near += i != j && std::abs(distance2(x[i], x[j]) - h * h) < 1e-6 * h * h ? 1 : 0;
  EXPECT_GT(near, 1000u);
  expect_exact<3, double>(x, std::vector<double>(x.size(), h), "pairs within ulps of h");
}

// Double searches test float copies of the positions against bounds around h^2 and test again in
// double only the candidates between them (CellIndex::hits64); the band widens with the extent of
// the set (float's error in x - origin). Pairs within 1e-6 h of the support, in a box 3 x 10^4 h wide
// (stored coordinates off by up to ~10^-3 h, so float alone would misjudge most of them), then with
// an outlier 10^12 away (the band covers every candidate): every path expect_exact checks for the
// box, find_all and the visitor with the outlier.
TEST(CellIndex, DoubleSearchesDecideNearTheSupportInDoubleWhateverTheExtent) {
  const double h = 0.37;
  Points<3, double> x = pairs_near_the_support(29, 300, {{3e4 * h, 3e4 * h, 40 * h}}, h,
                                               {-1e-3, -1e-6, -1e-9, -1e-15, 0.0, 1e-15, 1e-9, 1e-6, 1e-3});
  for (bool outlier : {false, true}) {
    if (outlier) x.push_back({{1e12, 0.0, 0.0}});
    // Pairs that float coordinates put on the other side of h.
    std::size_t misjudged = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      for (std::size_t j = 0; j < x.size(); ++j) {
        double s2 = 0;
        for (int k = 0; k < 3; ++k) {
          const float d = static_cast<float>(x[i][k]) - static_cast<float>(x[j][k]);
          s2 += double(d) * double(d);
        }
        misjudged += i != j && (s2 <= h * h) != (distance2(x[i], x[j]) <= h * h) ? 1 : 0;
      }
    EXPECT_GT(misjudged, 100u) << (outlier ? "with an outlier" : "box 3e4 h wide");
    const std::vector<double> hv(x.size(), h);
    if (!outlier) {
      expect_exact<3, double>(x, hv, "box 3e4 h wide");
      continue;
    }
    // The outlier needs the wide keys, which expect_exact's packed runs assert against.
    const NeighborList ref = all_pairs<3, double>(x, hv);
    for (int threads : {1, 2}) {
      ScopedThreads st(threads);
      CellIndex<3, double> ci;
      ci.build(x, hv);
      NeighborList a;
      ci.find_all(a);
      EXPECT_EQ(a.offsets, ref.offsets);
      EXPECT_EQ(a.indices, ref.indices);
      EXPECT_EQ(via_visitor(ci, x).indices, ref.indices);
    }
  }
}

// Cells holding hundreds of particles: their shared candidate blocks (from 320) are sorted by index
// once, so that the long rows come out ascending without a sort each; the lists must not change.
TEST(CellIndex, DenseCellsGiveAscendingRowsFromAnIndexSortedBlock) {
  const auto x = point_sets::uniform_random<3, double>(3000, 0.05);  // a box about 0.7 wide
  const std::vector<double> h(x.size(), 0.3);
  const NeighborList ref = all_pairs<3, double>(x, h);
  for (int threads : {1, 2}) {
    ScopedThreads st(threads);
    CellIndex<3, double> ci;
    ci.build(x, h);
    ASSERT_LE(ci.cell_count(), 27u);  // about 100+ particles per cell
    NeighborList a;
    ci.find_all(a);
    EXPECT_EQ(a.offsets, ref.offsets);
    EXPECT_EQ(a.indices, ref.indices);
  }
}

// Supports of 3.2 spacings: rows of ~137 neighbours from blocks on both sides of the 256 candidates
// whose hit masks find_all keeps in its work buffer (H = 3; longer blocks keep theirs in the spill),
// so rows longer than the rank sort takes are packed from kept masks of both kinds.
TEST(CellIndex, LongRowsFromHitMasksKeptInTheBufferAndTheSpill) {
  const auto x = point_sets::jittered_lattice<3, float>(1728, 1.0f, 0.2f);
  expect_exact<3, float>(x, std::vector<float>(x.size(), 3.2f), "3D float h = 3.2 spacings");
  std::vector<float> h(x.size(), 3.2f);
  for (std::size_t i = 0; i < h.size(); i += 4) h[i] = 2.1f;
  expect_exact<3, float>(x, h, "3D float, every fourth support 2.1 spacings");
}

// Blocks over the 256 candidates whose hit masks stay in the work buffer keep theirs in their
// traversal chunk's spill: from 257 to 319 candidates in block order, from 320 on sorted by id with
// the sort's order kept too, which the fill pass takes back instead of sorting again. Two densities
// side by side (about 270 and 675 candidates a full block at H = 1, about 110 and 280 at H = 2) give
// both kinds over several chunks (about 4096 particles each), with every fifth support smaller;
// then one index is reused on a smaller set, over a spill it does not clear.
TEST(CellIndex, LongBlocksKeepTheirHitMasksInTheSpill) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Points<3, float> x;
  for (int i = 0; i < 6000; ++i) x.push_back({{6.0f * u(rng), 10.0f * u(rng), 10.0f * u(rng)}});
  for (int i = 0; i < 10000; ++i) x.push_back({{6.0f + 4.0f * u(rng), 10.0f * u(rng), 10.0f * u(rng)}});
  std::vector<float> h(x.size(), 1.0f);
  for (std::size_t i = 0; i < h.size(); i += 5) h[i] = 0.7f;
  expect_exact<3, float>(x, h, "two densities, every fifth support 0.7");

  CellIndex<3, float> ci;
  NeighborList a;
  for (std::size_t n : {x.size(), std::size_t{9000}}) {
    const Points<3, float> xs(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(n));
    const std::vector<float> hs(n, 1.0f);
    ci.build(xs, hs);
    ci.find_all(a);
    const NeighborList ref = all_pairs<3, float>(xs, hs);
    EXPECT_EQ(a.offsets, ref.offsets) << n;
    EXPECT_EQ(a.indices, ref.indices) << n;
    // Blocks sorted by id too long to keep their order (over 2^16 by default; here over 500, of
    // the dense half's ~675) are sorted again by the fill pass, next to kept ones.
    CellIndex<3, float> cap;
    cap.limit_kept_order(500);
    cap.build(xs, hs);
    NeighborList b;
    cap.find_all(b);
    EXPECT_EQ(b.offsets, ref.offsets) << n;
    EXPECT_EQ(b.indices, ref.indices) << n;
  }
}

// SearchOptions::zero_support_rows = false (the solver's walls): the rows of points of support 0 are
// empty, every other row is the exact one, in cells of support-0 points only and in cells shared with
// points of full support; the default lists their exact duplicates, as all-pairs does.
template <class Real>
void expect_zero_support_rows_left_empty() {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points<3, Real> x;
  std::vector<Real> h;
  for (int i = 0; i < 3000; ++i) {  // "fluid" in [0, 6)^3, "walls" in [4, 10)^3: both alone and mixed
    x.push_back({{Real(6 * u(rng)), Real(6 * u(rng)), Real(6 * u(rng))}});
    h.push_back(Real(1));
    x.push_back({{Real(4 + 6 * u(rng)), Real(4 + 6 * u(rng)), Real(4 + 6 * u(rng))}});
    h.push_back(Real(0));
  }
  for (int i = 0; i < 20; ++i) {  // duplicates: of a wall point and of a fluid point, with support 0
    x.push_back(x[static_cast<std::size_t>(2 * i + 1)]);
    h.push_back(Real(0));
    x.push_back(x[static_cast<std::size_t>(2 * i)]);
    h.push_back(Real(0));
  }
  const NeighborList ref = all_pairs<3, Real>(x, h);
  for (const bool sorted : {true, false}) {
    CellIndex<3, Real> ci({.sorted_rows = sorted, .zero_support_rows = false});
    ci.build(x, h);
    NeighborList nl;
    ci.find_all(nl);
    std::vector<std::uint64_t> counts;
    const std::uint64_t pairs = ci.count_pairs(counts);
    std::uint64_t expected = 0, duplicates = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (h[i] == 0) {
        EXPECT_EQ(nl.count(i), 0u) << i;
        duplicates += ref.count(i);
        continue;
      }
      std::vector<std::uint32_t> row(nl.begin(i), nl.end(i)), want(ref.begin(i), ref.end(i));
      if (!sorted) std::sort(row.begin(), row.end());
      EXPECT_EQ(row, want) << i;
      EXPECT_EQ(counts[i], want.size()) << i;
      expected += want.size();
    }
    EXPECT_EQ(pairs, expected);
    EXPECT_GE(duplicates, 40u) << "the set should hold support-0 points with duplicates";
  }
  CellIndex<3, Real> all;  // the default keeps them
  all.build(x, h);
  NeighborList nl;
  all.find_all(nl);
  EXPECT_EQ(nl.offsets, ref.offsets);
  EXPECT_EQ(nl.indices, ref.indices);
}
TEST(CellIndex, ZeroSupportRowsLeftEmptyOnRequestFloat) {
  expect_zero_support_rows_left_empty<float>();
}
TEST(CellIndex, ZeroSupportRowsLeftEmptyOnRequestDouble) {
  expect_zero_support_rows_left_empty<double>();
}

// L distinct values: from [0, small) on even draws, from the whole unsigned range on odd ones.
[[maybe_unused]] std::vector<std::uint32_t> distinct_values(std::mt19937& rng, std::uint32_t L, int rep,
                                                            std::uint32_t small) {
  std::vector<std::uint32_t> v;
  while (v.size() < L) {
    const auto x = static_cast<std::uint32_t>(rep % 2 ? rng() : rng() % small);
    if (std::find(v.begin(), v.end(), x) == v.end()) v.push_back(x);
  }
  return v;
}

// The rank sorts that order short rows at each width the CPU has, on every length up to the limit (for
// AVX2 one to four registers a block, one to three blocks), distinct values on both sides of 2^31 (the
// signed compare's bias), against std::sort.
TEST(CellIndex, RankSortOrdersEveryRowLengthAtEveryWidth) {
  for (SimdPath path : {SimdPath::Scalar, SimdPath::Sse2, SimdPath::Avx2}) {
    if (path > best_simd_path()) continue;  // this CPU cannot run it (said below)
    std::mt19937 rng(96);
    for (std::uint32_t L = 1; L <= 96; ++L)
      for (int rep = 0; rep < 20; ++rep) {
        std::vector<std::uint32_t> v = distinct_values(rng, L, rep, 200);
        std::vector<std::uint32_t> in(v);
        in.resize(L + 8, 0xFFFFFFFFu);  // the 8 entries past L it may read
        std::vector<std::uint32_t> out(L, 0);
        if (path == SimdPath::Scalar) detail::rank_sort_scalar(in.data(), L, out.data());
#if defined(CELLSPH_CELL_INDEX_X86)
        if (path == SimdPath::Sse2) detail::rank_sort_sse2(in.data(), L, out.data());
        if (path == SimdPath::Avx2) detail::rank_sort_avx2<96>(in.data(), L, out.data());
#endif
        std::sort(v.begin(), v.end());
        ASSERT_EQ(out, v) << simd_path_name(path) << ", L = " << L << ", rep " << rep;
      }
  }
  if (best_simd_path() != SimdPath::Avx2) GTEST_SKIP() << "this CPU has no AVX2: its rank sort was not run";
}

// The distance tests of a block at each width give the scalar loop's bits, both bounds, at every block
// length, in 2D and 3D, with candidates on and around both bounds.
template <int Dim>
void expect_hits_alike_at_every_width() {
  std::mt19937 rng(7 + Dim);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> axis[Dim];
  for (auto& a : axis) {
    a.resize(64 + 8);
    for (float& c : a) c = u(rng);
  }
  const float* ax[Dim];
  for (int k = 0; k < Dim; ++k) ax[k] = axis[k].data();
  float xi[Dim];
  for (int k = 0; k < Dim; ++k) xi[k] = axis[k][5];  // candidate 5 sits on xi: d2 = 0
  float d0 = 0;                                      // candidate 9's d2 exactly, as the loops sum it
  for (int k = 0; k < Dim; ++k) d0 += (xi[k] - ax[k][9]) * (xi[k] - ax[k][9]);
  for (std::uint32_t m = 1; m <= 64; ++m)
    for (float hi2 : {0.0f, d0, 0.3f, 2.0f}) {
      const float lo2 = hi2 * 0.5f;
      std::uint64_t sure_ref = 0;
      const std::uint64_t ref = detail::hits64_scalar<Dim, true>(ax, xi, lo2, hi2, m, &sure_ref);
      if (m > 9 && hi2 == d0) {
        ASSERT_TRUE((ref >> 9) & 1u) << "the candidate at exactly hi2 is a hit";
      }
#if defined(CELLSPH_CELL_INDEX_X86)
      std::uint64_t sure = 0;
      const std::uint64_t sse2 = detail::hits64_sse2<Dim, true>(ax, xi, lo2, hi2, m, &sure);
      EXPECT_EQ(sse2, ref) << "sse2, m = " << m;
      EXPECT_EQ(sure, sure_ref) << "sse2, m = " << m;
      if (best_simd_path() == SimdPath::Avx2) {
        const std::uint64_t avx2 = detail::hits64_avx2<Dim, true>(ax, xi, lo2, hi2, m, &sure);
        EXPECT_EQ(avx2, ref) << "avx2, m = " << m;
        EXPECT_EQ(sure, sure_ref) << "avx2, m = " << m;
      }
#endif
    }
}

TEST(CellIndex, DistanceTestsGiveTheScalarBitsAtEveryWidth) {
  expect_hits_alike_at_every_width<2>();
  expect_hits_alike_at_every_width<3>();
}

// CELLSPH_SIMD's values: the three names, empty or unset for the best; anything else, or a path wider
// than the CPU's, is an input error naming the variable and the value.
TEST(CellIndex, SimdPathFromTheEnvironmentVariable) {
  EXPECT_EQ(parse_simd_path(nullptr, SimdPath::Avx2), SimdPath::Avx2);
  EXPECT_EQ(parse_simd_path("", SimdPath::Sse2), SimdPath::Sse2);
  EXPECT_EQ(parse_simd_path("scalar", SimdPath::Avx2), SimdPath::Scalar);
  EXPECT_EQ(parse_simd_path("sse2", SimdPath::Avx2), SimdPath::Sse2);
  EXPECT_EQ(parse_simd_path("avx2", SimdPath::Avx2), SimdPath::Avx2);
  try {
    (void)parse_simd_path("avx512", SimdPath::Avx2);
    ADD_FAILURE() << "avx512 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CELLSPH_SIMD=avx512"), std::string::npos) << e.what();
  }
  try {
    (void)parse_simd_path("avx2", SimdPath::Sse2);
    ADD_FAILURE() << "avx2 accepted on an SSE2-only CPU";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at most sse2"), std::string::npos) << e.what();
  }
}

#if defined(CELLSPH_SORT_NETWORK_AVX2)
// The bitonic networks that order rows of up to 64 (one, two, four or eight registers), on every
// length, values across the whole unsigned range, against std::sort. The entries past L that it reads
// hold small values, which would sort first were they not ignored; nothing past out[L - 1] is written.
TEST(CellIndex, SortNetworkOrdersEveryRowLength) {
  if (best_simd_path() != SimdPath::Avx2) GTEST_SKIP() << "this CPU has no AVX2: the rank sort runs instead";
  std::mt19937 rng(64);
  for (std::uint32_t L = 1; L <= 64; ++L)
    for (int rep = 0; rep < 40; ++rep) {
      std::vector<std::uint32_t> v = distinct_values(rng, L, rep, 100);
      if (rep == 2) std::sort(v.begin(), v.end());    // already ascending
      if (rep == 3) std::sort(v.rbegin(), v.rend());  // descending
      std::vector<std::uint32_t> in(v);
      in.resize(64, 0u);
      std::vector<std::uint32_t> out(L + 8, 0xABCDEFu);
      detail::sort_row_avx2(in.data(), L, out.data());
      std::sort(v.begin(), v.end());
      ASSERT_EQ(std::vector<std::uint32_t>(out.begin(), out.begin() + L), v)
          << "L = " << L << ", rep " << rep;
      for (std::uint32_t t = L; t < L + 8; ++t) ASSERT_EQ(out[t], 0xABCDEFu) << "wrote past L = " << L;
    }
}
#endif

// One support for all, given as a number (no array kept) or as an array: the same lists; a bad
// number is refused as a bad array is.
TEST(CellIndex, OneRadiusForAllEqualsAnArrayOfIt) {
  const auto x = point_sets::uniform_random<3, double>(5000, 1.0);
  const std::vector<double> h(x.size(), 2.3);
  const NeighborList ref = all_pairs<3, double>(x, h);
  CellIndex<3, double> ci;
  ci.build(x, 2.3);
  NeighborList a;
  ci.find_all(a);
  EXPECT_EQ(a.offsets, ref.offsets);
  EXPECT_EQ(a.indices, ref.indices);
  NeighborSearch<3, double> ns({.method = Method::CellIndex});
  ns.build(x, 2.3);
  NeighborList b;
  ns.find_all(b);
  EXPECT_EQ(b.indices, ref.indices);
  EXPECT_THROW(ci.build(x, -1.0), std::exception);
  EXPECT_THROW(ci.build(x, std::nan("")), std::exception);
}

// One index and one output list reused over builds of other sizes, sets and supports (the sort
// buffers and the lists keep their memory between builds): every build exact.
TEST(CellIndex, ReusedAcrossBuildsOfOtherSizes) {
  CellIndex<3, float> ci;
  NeighborList a;
  const std::vector<Points<3, float>> sets = {
      point_sets::uniform_random<3, float>(4000, 1.0f),
      point_sets::jittered_lattice<3, float>(500, 1.0f, 0.1f), point_sets::clustered<3, float>(6000, 1.0f),
      point_sets::uniform_random<3, float>(1, 1.0f), point_sets::uniform_in_cell_order<3, float>(3000, 1.0f)};
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const auto& x = sets[s];
    std::vector<float> h(x.size(), 2.0f);
    if (s == 2)
      for (std::size_t i = 0; i < h.size(); i += 3) h[i] = 1.3f;  // variable support
    ci.build(x, h);
    ci.find_all(a);
    const NeighborList ref = all_pairs<3, float>(x, h);
    EXPECT_EQ(a.offsets, ref.offsets) << "set " << s;
    EXPECT_EQ(a.indices, ref.indices) << "set " << s;
  }
}

TEST(CellIndex, WidensKeysWhenEq17DoesNotFit) {
  // 2^28 cells per axis in 2D: 58 bits of cell coordinates plus 9 index bits exceed 64, so the
  // packed key cannot hold it; the wide layout must take over and stay exact.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 6.0);
  Points<2, double> x;
  for (int i = 0; i < 300; ++i) x.push_back({{u(rng), u(rng)}});
  for (int i = 0; i < 100; ++i) x.push_back({{2.7e8 + u(rng), 2.7e8 + u(rng)}});
  for (int i = 0; i < 50; ++i) x.push_back({{u(rng), 2.7e8 + u(rng)}});
  const std::vector<double> h(x.size(), 1.0);
  CellIndex<2, double> ci;
  ci.build(x, h);
  EXPECT_TRUE(ci.wide_keys());
  EXPECT_GT(ci.index_bits() + ci.cell_bits(), 64);
  NeighborList a;
  ci.find_all(a);
  const NeighborList ref = all_pairs<2, double>(x, h);
  EXPECT_EQ(a.offsets, ref.offsets);
  EXPECT_EQ(a.indices, ref.indices);
  EXPECT_EQ(via_visitor(ci, x).indices, ref.indices);
}

TEST(CellIndex, PacksKeysWhenTheyFit) {
  const auto x = point_sets::jittered_lattice<3, float>(1000, 1.0f, 0.01f);
  CellIndex<3, float> ci({.subdivision = 2});
  ci.build(x, std::vector<float>(x.size(), 2.0f));
  EXPECT_FALSE(ci.wide_keys());
  EXPECT_EQ(ci.index_bits(), 10);  // 2^10 > 1000
  EXPECT_LE(ci.index_bits() + ci.cell_bits(), 64);
}

// Grids too wide for a key are cut at their last cell per axis, which stays exact. Three axes of
// 2^31 cells (96 bits of cell key) and one axis of 2^33 cells (a coordinate beyond 32 bits), each
// with a close pair at the far corner, which only an exact search finds.
TEST(CellIndex, CutsGridsBeyondSixtyFourBitsExactly) {
  const Points<3, double> x = {
      {{0, 0, 0}}, {{2.2e9, 2.2e9, 2.2e9}}, {{2.2e9, 2.2e9, 2.2e9 - 0.5}}, {{1, 1, 1}}};
  const std::vector<double> h(x.size(), 1.0);
  CellIndex<3, double> ci;
  ci.build(x, h);
  EXPECT_LE(ci.cell_bits(), 64);
  NeighborList nl;
  ci.find_all(nl);
  const NeighborList ref = all_pairs<3, double>(x, h);
  EXPECT_EQ(nl.offsets, ref.offsets);
  EXPECT_EQ(nl.indices, ref.indices);
  EXPECT_EQ(ref.pairs(), 2U);

  const Points<2, double> y = {{{0, 0}}, {{9.0e9, 0}}, {{9.0e9 - 0.75, 0.25}}, {{0.5, 0}}};
  const std::vector<double> hy(y.size(), 1.0);
  CellIndex<2, double> cj;
  cj.build(y, hy);
  cj.find_all(nl);
  const NeighborList refy = all_pairs<2, double>(y, hy);
  EXPECT_EQ(nl.indices, refy.indices);
  EXPECT_EQ(refy.pairs(), 4U);
}

TEST(CellIndex, RejectsSubdivisionBelowOne) {
  EXPECT_THROW((CellIndex<3, float>({.subdivision = 0})), InputError);
}

TEST(CellIndex, CandidatesShrinkWithSubdivision) {
  // The H-mask hugs the sphere more tightly as H grows (paper section 4.1).
  const auto x = point_sets::jittered_lattice<3, float>(4096, 1.0f, 0.01f);
  const std::vector<float> h(x.size(), 2.0f);
  std::map<int, std::uint64_t> cand;
  for (int H : {1, 2, 3}) {
    CellIndex<3, float> ci({.subdivision = H});
    ci.build(x, h);
    NeighborList nl;
    cand[H] = ci.find_all(nl);
  }
  EXPECT_LT(cand[2], cand[1]);
  EXPECT_LT(cand[3], cand[2]);
}

}  // namespace
}  // namespace cellsph
