#pragma once
// The neighbour search of the device backends: the sorted uniform grid of the CUDA write-up (the
// "particles" sample of the CUDA SDK): each particle's cell hash, a stable (key, index) sort, the
// positions gathered into cell order, each cell's start and end in the sorted order, then the rows.
// Cells have the support h as their size; the grid spans the particles' bounding box (found by a
// reduction each build), so every cell index fits the table and no particle is clamped.
//
// Rows are exact and canonical: row i holds every j != i with distance2(x_i, x_j) <= h_i^2 (the test of
// the CPU search, neighbors/neighbor_list.hpp), in ascending j (each row is sorted after it is filled:
// the cells deliver their particles in cell order). So the passes sum over exactly the neighbours of
// the CPU backend, in the same order, and the host-emulated device gives the CPU's bits.
//
// Two row kinds: the fluid particles' rows (all kinds of neighbours), and the wall particles' rows of
// fluid neighbours (Adami walls: boundary/wall_neighbors.hpp gives the same set, since every particle
// has the same support h).
//
// Every function here is a CELLSPH_HD pass, run by the device driver over device memory.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/hmask.hpp"

namespace cellsph {

inline constexpr std::uint32_t kEmptyCell = 0xffffffffu;

template <int Dim, class Real>
struct BoundsMax {
  Vec<Dim, Real> hi = Vec<Dim, Real>::filled(static_cast<Real>(-HUGE_VALF));
  Vec<Dim, Real> neg_lo =
      Vec<Dim, Real>::filled(static_cast<Real>(-HUGE_VALF));  // max of -x: the minimum, negated
  CELLSPH_HD static BoundsMax max_of(const BoundsMax& a, const BoundsMax& b) {
    BoundsMax r;
    for (int k = 0; k < Dim; ++k) {
      r.hi[k] = a.hi[k] > b.hi[k] ? a.hi[k] : b.hi[k];
      r.neg_lo[k] = a.neg_lo[k] > b.neg_lo[k] ? a.neg_lo[k] : b.neg_lo[k];
    }
    return r;
  }
};

template <int Dim, class Real>
struct BoundsPass {
  const Vec<Dim, Real>* x;
  CELLSPH_HD BoundsMax<Dim, Real> operator()(std::size_t i) const { return {x[i], -x[i]}; }
};

// The grid over the particles' bounding box. Cells are a little larger than the support (by
// kCellInflation, the CPU grids' margin, neighbors/hmask.hpp) and coordinates are computed in double: a pair
// that passes the row test distance2 <= h^2 in Real is then never two cells apart, whatever the rounding of a
// coordinate near a cell face (with cells of exactly h, computed in Real, a lattice pair at distance h could
// land two cells apart and be lost: DeviceGrid.LatticeWithPairsAtTheSupportGivesTheExactRows). The margin
// covers float's rounding of the distance test (a few 1e-7) and double's of a coordinate over at most 2^30
// cells (about 1e-7 of a cell); it costs about 2^-16 more candidates.

template <int Dim, class Real>
struct GridGeometry {
  double lo[Dim] = {};
  double inv_cell = 0;
  std::uint32_t dims[Dim] = {};

  CELLSPH_HD std::uint32_t coord(Real x, int a) const {
    const double q = std::floor((static_cast<double>(x) - lo[a]) * inv_cell);
    if (!(q > 0)) return 0;  // also NaN (the stability check stops such a run after the step)
    const auto c = static_cast<std::uint32_t>(q < double(dims[a] - 1) ? q : double(dims[a] - 1));
    return c;
  }
  CELLSPH_HD std::uint32_t cell_of(const Vec<Dim, Real>& x) const {
    std::uint32_t key = 0;
    for (int a = Dim - 1; a >= 0; --a) key = key * dims[a] + coord(x[a], a);
    return key;
  }
};

template <int Dim, class Real>
struct CellKeyPass {
  GridGeometry<Dim, Real> g;
  const Vec<Dim, Real>* x;
  std::uint32_t* key;
  std::uint32_t* idx;
  CELLSPH_HD void operator()(std::size_t i) const {
    key[i] = g.cell_of(x[i]);
    idx[i] = static_cast<std::uint32_t>(i);
  }
};

// Sorted order k: the positions gathered into cell order (the write-up's reorder), so the row passes
// read the candidates of one cell contiguously.
template <int Dim, class Real>
struct GatherPositionsPass {
  const Vec<Dim, Real>* x;
  const std::uint32_t* sorted_idx;
  Vec<Dim, Real>* xs;
  CELLSPH_HD void operator()(std::size_t k) const { xs[k] = x[sorted_idx[k]]; }
};

struct ClearCellsPass {
  std::uint32_t* start;
  CELLSPH_HD void operator()(std::size_t c) const { start[c] = kEmptyCell; }
};

// Sorted order k: where a cell's run of keys begins and ends.
struct CellBoundsPass {
  const std::uint32_t* sorted_key;
  std::size_t n;
  std::uint32_t* start;
  std::uint32_t* end;
  CELLSPH_HD void operator()(std::size_t k) const {
    const std::uint32_t c = sorted_key[k];
    if (k == 0 || sorted_key[k - 1] != c) start[c] = static_cast<std::uint32_t>(k);
    if (k + 1 == n || sorted_key[k + 1] != c) end[c] = static_cast<std::uint32_t>(k + 1);
  }
};

// Row of particle i: counted (rows == nullptr: count[i] = its length) or filled (rows + offsets[i],
// sorted ascending). only_fluid: the wall rows (fluid neighbours only).
template <int Dim, class Real, class Offset>
struct GridRowPass {
  // Rows up to this length are gathered and sorted in a per-thread buffer and written once. On an H200
  // (10^6 fluid particles) the filling pass took 3.1x the counting one when it sorted in place in device
  // memory, 1.7x with the buffer (docs/gpu.md, "Measured on an H200").
  static constexpr std::uint32_t kLocalRow = 128;

  GridGeometry<Dim, Real> g;
  const Vec<Dim, Real>* x;
  const Real* h;
  const std::uint8_t* kind;
  const Vec<Dim, Real>* xs;
  const std::uint32_t* sorted_idx;
  const std::uint32_t* start;
  const std::uint32_t* end;
  bool only_fluid;
  std::uint32_t* count;   // counting; filling reads it
  const Offset* offsets;  // filling
  std::uint32_t* rows;    // filling

  CELLSPH_HD void operator()(std::size_t i) const {
    if (!rows) {
      std::uint32_t m = 0;
      for_each_neighbor(i, [&](std::uint32_t) { ++m; });
      count[i] = m;
    } else if (count[i] <= kLocalRow) {
      std::uint32_t buf[kLocalRow];
      std::uint32_t m = 0;
      for_each_neighbor(i, [&](std::uint32_t j) { buf[m++] = j; });
      sort_ascending(buf, m);
      std::uint32_t* out = rows + offsets[i];
      for (std::uint32_t p = 0; p < m; ++p) out[p] = buf[p];
    } else {
      std::uint32_t* out = rows + offsets[i];
      std::uint32_t m = 0;
      for_each_neighbor(i, [&](std::uint32_t j) { out[m++] = j; });
      sort_ascending(out, m);
    }
  }

 private:
  // f(j) for every j != i within h_i of particle i, over its 3^Dim cells, the first axis fastest.
  template <class F>
  CELLSPH_HD void for_each_neighbor(std::size_t i, F&& f) const {
    const Vec<Dim, Real> xi = x[i];
    const Real hi2 = h[i] * h[i];
    std::uint32_t lo_c[Dim], hi_c[Dim], c[Dim];
    for (int a = 0; a < Dim; ++a) {
      const std::uint32_t ca = g.coord(xi[a], a);
      lo_c[a] = ca > 0 ? ca - 1 : 0;
      hi_c[a] = ca + 1 < g.dims[a] ? ca + 1 : ca;
      c[a] = lo_c[a];
    }
    for (;;) {
      std::uint32_t cell = 0;
      for (int a = Dim - 1; a >= 0; --a) cell = cell * g.dims[a] + c[a];
      const std::uint32_t s = start[cell];
      if (s != kEmptyCell) {
        for (std::uint32_t k = s; k < end[cell]; ++k) {
          const std::uint32_t j = sorted_idx[k];
          if (j == i || (only_fluid && kind[j] != 0)) continue;
          if (distance2(xi, xs[k]) <= hi2) f(j);
        }
      }
      int a = 0;
      while (a < Dim && c[a] == hi_c[a]) c[a] = lo_c[a], ++a;
      if (a == Dim) break;
      ++c[a];
    }
  }

  // Insertion sort: rows are short and nearly sorted by cell.
  CELLSPH_HD static void sort_ascending(std::uint32_t* v, std::uint32_t m) {
    for (std::uint32_t p = 1; p < m; ++p) {
      const std::uint32_t e = v[p];
      std::uint32_t q = p;
      for (; q > 0 && v[q - 1] > e; --q) v[q] = v[q - 1];
      v[q] = e;
    }
  }
};

}  // namespace cellsph
