// Cross-method suite: every method, in 2D and 3D, float and double, with subdivision H = 1, 2, 3
// where the method has cells, against an independent brute-force reference (a plain serial double
// loop with the relation of neighbor_list.hpp: j != i and distance2(x_i, x_j) <= h_i * h_i).
// Results must be equal row by row, for 1 and 2 threads, and the visitor must visit exactly the
// CSR pairs, each i on one thread in one consecutive run, in the same order for any thread count.
//
// Test names carry the method name (e.g. `Methods/CrossMethod.Clustered/CellIndex_H2`), so
// `--gtest_filter=-*CellIndex*` runs the suite without one method.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/neighbors/point_sets.hpp"

namespace cellsph {
namespace {

struct MethodParam {
  Method method;
  int subdivision;
};

std::string param_name(const MethodParam& param) {
  std::string name;
  switch (param.method) {
    case Method::AllPairs:
      name = "AllPairs";
      break;
    case Method::SpatialHash:
      name = "SpatialHash";
      break;
    case Method::CellIndex:
      name = "CellIndex";
      break;
    case Method::SortedGrid:
      name = "SortedGrid";
      break;
    case Method::KdTree:
      name = "KdTree";
      break;
  }
  return name + "_H" + std::to_string(param.subdivision);
}

std::string param_test_name(const ::testing::TestParamInfo<MethodParam>& info) {
  return param_name(info.param);
}

// Readable parameter in failure messages.
void PrintTo(const MethodParam& p, std::ostream* os) {
  *os << param_name(p);
}

// Every method of kAllMethods; H = 2, 3 only for the methods built on cells.
std::vector<MethodParam> all_params() {
  std::vector<MethodParam> out;
  for (Method m : kAllMethods) {
    const bool cells = m == Method::SpatialHash || m == Method::CellIndex || m == Method::SortedGrid;
    for (int H = 1; H <= (cells ? 3 : 1); ++H) out.push_back({m, H});
  }
  return out;
}

template <int Dim, class Real>
using Points = std::vector<Vec<Dim, Real>>;

// The reference, written independently of every method (and of the AllPairs class).
template <int Dim, class Real>
NeighborList brute_force(const Points<Dim, Real>& x, const std::vector<Real>& h) {
  NeighborList nl;
  nl.offsets.push_back(0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t j = 0; j < x.size(); ++j)
      if (j != i && distance2(x[i], x[j]) <= h[i] * h[i]) nl.indices.push_back(static_cast<std::uint32_t>(j));
    nl.offsets.push_back(nl.indices.size());
  }
  return nl;
}

::testing::AssertionResult same_lists(const NeighborList& ref, const NeighborList& got) {
  if (got.size() != ref.size())
    return ::testing::AssertionFailure() << "rows " << got.size() << " != " << ref.size();
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const std::vector<std::uint32_t> a(ref.begin(i), ref.end(i)), b(got.begin(i), got.end(i));
    if (a != b) {
      auto f = ::testing::AssertionFailure();
      f << "row " << i << ": expected " << a.size() << " neighbours, got " << b.size() << "; missing:";
      for (auto j : a)
        if (!std::binary_search(b.begin(), b.end(), j)) f << ' ' << j;
      f << "; extra:";
      for (auto j : b)
        if (!std::binary_search(a.begin(), a.end(), j)) f << ' ' << j;
      return f;
    }
  }
  if (got.pairs() != ref.pairs()) return ::testing::AssertionFailure() << "pair counts differ";
  return ::testing::AssertionSuccess();
}

struct Visit {
  std::uint32_t i, j;
  int thread;
};

// Runs the visitor and checks it against the CSR lists; returns the visit order per row.
template <int Dim, class Real>
::testing::AssertionResult visitor_matches(const NeighborSearch<Dim, Real>& ns, const Points<Dim, Real>& x,
                                           const NeighborList& ref,
                                           std::vector<std::vector<std::uint32_t>>& order) {
  const std::size_t n = x.size();
  std::vector<std::vector<Visit>> per_thread(static_cast<std::size_t>(max_threads()));
  bool r2_ok = true;
  const std::uint64_t candidates = ns.for_each_pair([&](std::uint32_t i, std::uint32_t j, Real r2) {
    const int t = thread_id();
    per_thread[static_cast<std::size_t>(t)].push_back({i, j, t});
    if (r2 != distance2(x[i], x[j])) r2_ok = false;  // benign race: only ever set to false
  });
  if (!r2_ok) return ::testing::AssertionFailure() << "visitor got an r2 other than distance2(x_i, x_j)";
  if (candidates < ref.pairs())
    return ::testing::AssertionFailure() << candidates << " distance tests for " << ref.pairs() << " pairs";
  order.assign(n, {});
  std::vector<int> owner(n, -1);
  for (const auto& visits : per_thread) {
    for (std::size_t k = 0; k < visits.size(); ++k) {
      const Visit& v = visits[k];
      if (v.i >= n || v.j >= n) return ::testing::AssertionFailure() << "index out of range";
      // All calls for one i: one thread, one consecutive run.
      if (owner[v.i] == -1) {
        owner[v.i] = v.thread;
      } else if (owner[v.i] != v.thread || visits[k - 1].i != v.i) {
        return ::testing::AssertionFailure() << "calls for i = " << v.i << " are not one consecutive run";
      }
      order[v.i].push_back(v.j);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::uint32_t> row = order[i];
    std::sort(row.begin(), row.end());
    if (row != std::vector<std::uint32_t>(ref.begin(i), ref.end(i)))
      return ::testing::AssertionFailure() << "visitor row " << i << " differs from the CSR row";
  }
  return ::testing::AssertionSuccess();
}

// The core check of every case.
template <int Dim, class Real>
void expect_exact(const MethodParam& p, const Points<Dim, Real>& x, const std::vector<Real>& h) {
  const NeighborList ref = brute_force(x, h);
  std::vector<std::vector<std::uint32_t>> order_by_threads[2];
  for (int threads : {1, 2}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    ScopedThreads scoped(threads);
    NeighborSearch<Dim, Real> ns({.method = p.method, .subdivision = p.subdivision});
    ns.build(x, h);
    NeighborList nl;
    ns.find_all(nl);
    EXPECT_TRUE(same_lists(ref, nl));
    EXPECT_EQ(ns.stats().pairs, ref.pairs());
    EXPECT_GE(ns.stats().candidates, ref.pairs());
    EXPECT_TRUE(visitor_matches(ns, x, ref, order_by_threads[threads - 1]));
  }
  EXPECT_TRUE(order_by_threads[0] == order_by_threads[1]) << "visit order depends on the thread count";
}

template <int Dim, class Real>
void expect_exact(const MethodParam& p, const Points<Dim, Real>& x, Real radius) {
  expect_exact<Dim, Real>(p, x, std::vector<Real>(x.size(), radius));
}

// Calls f.template operator()<Dim, Real>() for 2D/3D x float/double.
template <class F>
void for_all_types(F&& f) {
  {
    SCOPED_TRACE("2D float");
    f.template operator()<2, float>();
  }
  {
    SCOPED_TRACE("2D double");
    f.template operator()<2, double>();
  }
  {
    SCOPED_TRACE("3D float");
    f.template operator()<3, float>();
  }
  {
    SCOPED_TRACE("3D double");
    f.template operator()<3, double>();
  }
}

// A lattice shifted by `offset`, built in double and rounded once to Real.
template <int Dim, class Real>
Points<Dim, Real> shifted_lattice(std::size_t n, double s, double jitter, double offset) {
  const auto base = point_sets::jittered_lattice<Dim, double>(n, s, jitter, 11);
  Points<Dim, Real> x(base.size());
  for (std::size_t i = 0; i < base.size(); ++i)
    for (int k = 0; k < Dim; ++k) x[i][k] = static_cast<Real>(base[i][k] + offset);
  return x;
}

// point_sets::jittered_lattice<Dim, float> trips -Wdouble-promotion inside point_sets.hpp (float
// jitter times a double); the lattice is generated in double and rounded once instead.
template <int Dim, class Real>
Points<Dim, Real> lattice(std::size_t n, double s, double jitter, std::uint64_t seed) {
  const auto base = point_sets::jittered_lattice<Dim, double>(n, s, jitter, seed);
  Points<Dim, Real> x(base.size());
  for (std::size_t i = 0; i < base.size(); ++i)
    for (int k = 0; k < Dim; ++k) x[i][k] = static_cast<Real>(base[i][k]);
  return x;
}

class CrossMethod : public ::testing::TestWithParam<MethodParam> {};

TEST_P(CrossMethod, JitteredLattice) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = lattice<Dim, Real>(1000, 1, 0.3, 5);
    for (Real r : {Real(1), Real(2)}) expect_exact<Dim, Real>(GetParam(), x, r);
  });
}

// Jitter 0: neighbours at distance exactly r (the test is <=), points on cell faces.
TEST_P(CrossMethod, IntegerLatticeOnCellFaces) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = lattice<Dim, Real>(1000, 1, 0, 1);
    for (Real r : {Real(1), Real(2)}) expect_exact<Dim, Real>(GetParam(), x, r);
  });
}

// Spacing 0.1 is not representable: lattice distances fall just below or above r.
TEST_P(CrossMethod, DecimalLatticeSpacing0p1) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = lattice<Dim, Real>(1000, 0.1, 0, 1);
    for (Real r : {Real(0.1), Real(0.2)}) expect_exact<Dim, Real>(GetParam(), x, r);
  });
}

TEST_P(CrossMethod, UniformRandom) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = point_sets::uniform_random<Dim, Real>(1500, Real(1), 7);
    expect_exact<Dim, Real>(GetParam(), x, Real(1.7));
  });
}

TEST_P(CrossMethod, Clustered) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = point_sets::clustered<Dim, Real>(1500, Real(1), 8, 9);
    expect_exact<Dim, Real>(GetParam(), x, Real(1));
  });
}

TEST_P(CrossMethod, AllPointsInOneCell) {
  for_all_types([&]<int Dim, class Real>() {
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(5.0, 5.05);
    Points<Dim, Real> x(300);
    for (auto& p : x)
      for (int k = 0; k < Dim; ++k) p[k] = static_cast<Real>(u(rng));
    expect_exact<Dim, Real>(GetParam(), x, Real(1));
  });
}

TEST_P(CrossMethod, DuplicatePoints) {
  for_all_types([&]<int Dim, class Real>() {
    const auto base = lattice<Dim, Real>(200, 1, 0.2, 6);
    Points<Dim, Real> x;
    for (int copy = 0; copy < 3; ++copy) x.insert(x.end(), base.begin(), base.end());
    expect_exact<Dim, Real>(GetParam(), x, Real(1));
    // h = 0: only the exact duplicates are neighbours.
    expect_exact<Dim, Real>(GetParam(), x, Real(0));
  });
}

// The solver's walls: particles of support 0 (no rows but their exact duplicates) next to particles
// of support 1. Whole cells of support 0 (the first 35% along axis 0), cells that mix both (up to 60%,
// and the duplicates), and cells of support 1 beyond, so a traversal passes from skipped cells to full ones.
TEST_P(CrossMethod, ZeroSupportRegions) {
  for_all_types([&]<int Dim, class Real>() {
    const auto base = lattice<Dim, Real>(600, 0.5, 0.3, 14);
    Points<Dim, Real> x(base.begin(), base.end());
    x.insert(x.end(), base.begin(), base.begin() + 100);  // duplicates of some points
    double top = 0;
    for (const auto& p : x) top = std::max(top, double(p[0]));
    std::vector<Real> h(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double a = double(x[i][0]) / top;
      h[i] = a < 0.35 || (a < 0.6 && i % 2 == 0) ? Real(0) : Real(1);
    }
    expect_exact<Dim, Real>(GetParam(), x, h);
  });
}

TEST_P(CrossMethod, OnePointAndZeroPoints) {
  for_all_types([&]<int Dim, class Real>() {
    Points<Dim, Real> one(1);
    one[0][0] = Real(-3);
    expect_exact<Dim, Real>(GetParam(), one, Real(1));
    expect_exact<Dim, Real>(GetParam(), Points<Dim, Real>{}, Real(1));
  });
}

TEST_P(CrossMethod, NegativeCoordinates) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = shifted_lattice<Dim, Real>(800, 1.0, 0.3, -1000.25);
    expect_exact<Dim, Real>(GetParam(), x, Real(1.5));
  });
}

// Offset 1e6: in float the coordinates keep only ~1/16 of precision, differences stay exact.
TEST_P(CrossMethod, LargeCoordinates) {
  for_all_types([&]<int Dim, class Real>() {
    for (double offset : {1e6, -1e6}) {
      const auto x = shifted_lattice<Dim, Real>(800, 1.0, 0.3, offset);
      expect_exact<Dim, Real>(GetParam(), x, Real(1.5));
    }
  });
}

// Per-particle support spanning a factor of 10 (paper section 4.1): the relation is asymmetric and
// smaller supports skip mask cells.
TEST_P(CrossMethod, VariableSupport10x) {
  for_all_types([&]<int Dim, class Real>() {
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int set = 0; set < 2; ++set) {
      const auto x = set == 0 ? point_sets::uniform_random<Dim, Real>(1200, Real(1), 8)
                              : point_sets::clustered<Dim, Real>(1200, Real(1), 5, 13);
      std::vector<Real> h(x.size());
      for (auto& v : h) v = static_cast<Real>(0.25 * std::pow(10.0, u(rng)));
      expect_exact<Dim, Real>(GetParam(), x, h);
    }
  });
}

// Neighbours placed in the farthest cells of the H-mask: for every gap vector g between the home
// cell and a mask cell (in cell units) and every direction, particle i sits at the home cell's
// corner facing that cell (offset g_k + 1 along each axis), j just inside the mask cell's nearest corner, and
// h_i is set so that (h_i / h')^2 = |g|^2 + 0.02. j is then a neighbour only reachable through that mask
// cell, and a mask or per-particle cell skip that is too tight by more than 1% loses it.
template <int Dim, class Real>
void expect_exact_at_mask_edges(const MethodParam& p) {
  const int H = p.subdivision;
  const double cell = 1.0 / H * kCellInflation;  // h' for max h = 1
  Points<Dim, Real> x(1);                        // x[0] = origin anchors the bounding box
  std::vector<Real> h(1, Real(1));
  std::array<int, Dim> g{};
  std::size_t blocks = 0;
  while (true) {
    int g2 = 0;
    for (int k = 0; k < Dim; ++k) g2 += g[k] * g[k];
    if ((g2 + 0.02) * cell * cell <= 1.0) {
      for (int signs = 0; signs < (1 << Dim); ++signs, ++blocks) {
        const std::array<long, 3> home = {10 + 40 * static_cast<long>(blocks % 16),
                                          10 + 40 * static_cast<long>(blocks / 16), 10};
        Vec<Dim, Real> xi, xj;
        for (int k = 0; k < Dim; ++k) {
          const int s = (signs >> k) & 1 ? 1 : -1;
          const double c = static_cast<double>(home[static_cast<std::size_t>(k)]);
          const double pi = (c + (s > 0 ? 0.999 : 0.001)) * cell;
          const int o = s * (g[k] + 1);  // gap g_k: offset g_k + 1 cells
          const double pj = o > 0 ? (c + o + 0.0005) * cell : (c + o + 1 - 0.0005) * cell;
          xi[k] = static_cast<Real>(pi);
          xj[k] = static_cast<Real>(pj);
        }
        x.push_back(xi);
        h.push_back(static_cast<Real>(cell * std::sqrt(g2 + 0.02)));
        x.push_back(xj);
        h.push_back(Real(0.1));
      }
    }
    int k = 0;
    while (k < Dim && ++g[k] > H) g[k++] = 0;
    if (k == Dim) break;
  }
  // The construction must really produce one neighbour per block.
  std::size_t found = 0;
  for (std::size_t b = 0; b < blocks; ++b)
    found += distance2(x[1 + 2 * b], x[2 + 2 * b]) <= h[1 + 2 * b] * h[1 + 2 * b] ? 1U : 0U;
  ASSERT_GT(blocks, 0U);
  EXPECT_EQ(found, blocks);
  expect_exact<Dim, Real>(p, x, h);
}

TEST_P(CrossMethod, NeighboursInTheFarthestMaskCells) {
  for_all_types([&]<int Dim, class Real>() { expect_exact_at_mask_edges<Dim, Real>(GetParam()); });
}

// Exact on every finite input (issue: one far outlier, 2^31-wide ranges, tiny and huge supports).
// A cluster with outliers 10^12 away along every axis and a close pair out there: a dense grid would
// need 10^39 cells, a key 3 x 40 bits; the methods wrap or cut their grids instead of refusing.
TEST_P(CrossMethod, FarOutliersOfACluster) {
  for_all_types([&]<int Dim, class Real>() {
    auto x = point_sets::clustered<Dim, Real>(600, Real(1), 4, 21);
    for (int k = 0; k < Dim; ++k) {
      Vec<Dim, Real> far{};
      far[k] = Real(1e12);
      x.push_back(far);
      far[(k + 1) % Dim] = Real(0.25);  // 0.25 from the outlier before: a pair far from the rest
      x.push_back(far);
    }
    Vec<Dim, Real> neg{};
    neg[0] = Real(-1e12);
    x.push_back(neg);
    expect_exact<Dim, Real>(GetParam(), x, Real(0.5));
  });
}

// Coordinates spread over [0, 2^31] (2^31 cells of size 1 per axis) plus a jittered block at the top
// corner, where float coordinates are 128 apart and collapse into duplicates.
TEST_P(CrossMethod, CoordinateRangeOf2To31) {
  for_all_types([&]<int Dim, class Real>() {
    auto x = point_sets::uniform_random<Dim, Real>(400, Real(2147483648.0), 23);
    const auto block = shifted_lattice<Dim, Real>(300, 0.5, 0.2, 2147483000.0);
    x.insert(x.end(), block.begin(), block.end());
    expect_exact<Dim, Real>(GetParam(), x, Real(1));
  });
}

// Supports so small that squared distances lose precision or underflow to 0 (then every pair closer
// than about sqrt(denorm_min) passes distance2 <= h^2, and must be found), and supports whose square
// overflows (distance2 <= inf: every point is a neighbour).
TEST_P(CrossMethod, TinyAndHugeSupports) {
  for_all_types([&]<int Dim, class Real>() {
    const double tiny[] = {1e-30, sizeof(Real) == 4 ? 1e-24 : 1e-170, sizeof(Real) == 4 ? 1e-44 : 1e-300};
    for (double s : tiny) {
      SCOPED_TRACE("spacing 10^" + std::to_string(std::lround(std::log10(s))));
      const auto base = lattice<Dim, double>(300, 1, 0.3, 31);
      Points<Dim, Real> x(base.size());
      for (std::size_t i = 0; i < base.size(); ++i)
        for (int k = 0; k < Dim; ++k) x[i][k] = static_cast<Real>(base[i][k] * s);
      expect_exact<Dim, Real>(GetParam(), x, static_cast<Real>(1.5 * s));
    }
    // h^2 overflows: 1e20 in float, 1e160 in double; mixed with ordinary supports, and points far
    // beyond h (1e30, 1e200) that are its neighbours all the same.
    auto x = lattice<Dim, Real>(300, 1, 0.3, 32);
    for (double far : {sizeof(Real) == 4 ? 1e30 : 1e200, sizeof(Real) == 4 ? -3e38 : -1e300}) {
      Vec<Dim, Real> p{};
      p[Dim - 1] = static_cast<Real>(far);
      x.push_back(p);
    }
    std::vector<Real> h(x.size(), Real(1.5));
    h[7] = static_cast<Real>(sizeof(Real) == 4 ? 1e20 : 1e160);
    expect_exact<Dim, Real>(GetParam(), x, h);
  });
}

// Coordinates near the largest finite values: differences overflow to inf (never a neighbour).
TEST_P(CrossMethod, CoordinatesNearTheLargestFinite) {
  for_all_types([&]<int Dim, class Real>() {
    const double big = sizeof(Real) == 4 ? 3e38 : 1e308;
    auto x = lattice<Dim, Real>(200, 1, 0.3, 33);
    for (double sgn : {1.0, -1.0})
      for (double d : {0.0, 0.5}) {
        Vec<Dim, Real> p{};
        p[0] = static_cast<Real>(sgn * big);
        p[Dim - 1] = static_cast<Real>(d);
        x.push_back(p);
      }
    expect_exact<Dim, Real>(GetParam(), x, Real(1));
  });
}

INSTANTIATE_TEST_SUITE_P(Methods, CrossMethod, ::testing::ValuesIn(all_params()), param_test_name);

// Spatial Hashing with tiny tables: many cells per bucket and mask cells hashing to one bucket.
TEST(SpatialHash, TinyTablesStayExact) {
  for_all_types([&]<int Dim, class Real>() {
    const auto x = lattice<Dim, Real>(250, 1, 0.4, 3);
    for (std::size_t m : {1, 7})
      for (int H : {1, 2}) {
        SCOPED_TRACE("M " + std::to_string(m) + " H " + std::to_string(H));
        const std::vector<Real> h(x.size(), Real(1.5));
        NeighborSearch<Dim, Real> ns({.method = Method::SpatialHash, .subdivision = H, .hash_table_size = m});
        ns.build(x, h);
        NeighborList nl;
        ns.find_all(nl);
        EXPECT_TRUE(same_lists(brute_force(x, h), nl));
      }
  });
}

TEST(SpatialHash, DefaultTableSizeIsPrimeAtLeastTwiceN) {
  EXPECT_EQ((SpatialHash<3, float>::default_table_size(1000)), 2003U);
  EXPECT_EQ((SpatialHash<3, float>::default_table_size(0)), 2U);
  SpatialHash<2, double> sh;
  const std::vector<Vec<2, double>> x(10);
  const std::vector<double> h(10, 1.0);
  sh.build(x, h);
  EXPECT_EQ(sh.table_size(), 23U);
}

// A dense grid over this box would have 10^18 cells: the grid wraps, stays small and exact.
TEST(SortedGrid, WrapsADenseGridTooLargeForMemory) {
  std::vector<Vec<3, double>> x = {{{0.0, 0.0, 0.0}}, {{1e4, 1e4, 1e4}}, {{1e4, 1e4, 1e4 + 5e-3}}};
  for (int i = 0; i < 200; ++i)  // a small cluster that shares slots with far cells
    x.push_back({{1e-3 * (i % 7), 1e-3 * (i / 7 % 5), 1e-3 * (i / 35)}});
  const std::vector<double> h(x.size(), 1e-2);
  SortedGrid<3, double> sg;
  sg.build(x, h);
  EXPECT_TRUE(sg.wrapped());
  EXPECT_LT(sg.memory_bytes(), std::size_t{64} << 20);
  NeighborList nl;
  build_csr(sg, x.size(), nl);
  EXPECT_TRUE(same_lists(brute_force(x, h), nl));
}

// The benchmark's uniform-cells set: the uniform set's points, reordered so that the cell of side 2 s
// (last axis slowest) never decreases along the array, and the same neighbour pairs between the same
// points (every method against all-pairs).
TEST_P(CrossMethod, UniformInCellOrderIsTheUniformSetSortedByCell) {
  const auto u = point_sets::uniform_random<3, double>(1500, 1.0);
  const auto c = point_sets::uniform_in_cell_order<3, double>(1500, 1.0);
  ASSERT_EQ(u.size(), c.size());
  auto lex = [](const Vec<3, double>& a, const Vec<3, double>& b) {
    return std::tie(a[0], a[1], a[2]) < std::tie(b[0], b[1], b[2]);
  };
  auto su = u, sc = c;
  std::sort(su.begin(), su.end(), lex);
  std::sort(sc.begin(), sc.end(), lex);
  EXPECT_TRUE(std::equal(su.begin(), su.end(), sc.begin(), [&](const auto& a, const auto& b) {
    return !lex(a, b) && !lex(b, a);
  })) << "not a permutation of the uniform set";
  const double side = std::cbrt(1500.0);
  const auto cells = static_cast<long>(std::ceil(side / 2));
  long last = -1;
  for (const auto& p : c) {
    long k = 0;
    for (int a = 2; a >= 0; --a) k = k * cells + static_cast<long>(std::floor(p[a] / 2));
    ASSERT_GE(k, last);
    last = k;
  }
  std::vector<double> h(c.size(), 2.0);
  expect_exact<3, double>(GetParam(), c, h);
}

}  // namespace
}  // namespace cellsph

namespace cellsph {
namespace {

// A NaN coordinate or support would silently drop pairs from a grid; the methods refuse it.
TEST(GridAndTreeMethods, RefuseNonFiniteInput) {
  for (Method m : {Method::SpatialHash, Method::SortedGrid, Method::KdTree}) {
    SCOPED_TRACE(std::string(method_name(m)));
    NeighborSearch<2, float> ns({.method = m});
    std::vector<Vec<2, float>> x = {{{0.0F, 0.0F}}, {{1.0F, std::nanf("")}}};
    EXPECT_THROW(ns.build(x, std::vector<float>(2, 1.0F)), std::logic_error);
    x[1][1] = 1.0F;
    EXPECT_THROW(ns.build(x, std::vector<float>{1.0F, std::numeric_limits<float>::infinity()}),
                 std::logic_error);
    EXPECT_THROW(ns.build(x, std::vector<float>{1.0F, -1.0F}), std::logic_error);
    EXPECT_NO_THROW(ns.build(x, std::vector<float>(2, 1.0F)));
  }
}

}  // namespace
}  // namespace cellsph
