#pragma once
// Sorted uniform grid, as in the CUDA SDK "particles" sample (write-up 003): a dense grid over the
// bounding box, the cell hash of a particle is its linear cell index, the (hash, index) pairs are
// sorted by hash, positions are reordered into that order, and cellStart / cellEnd arrays over the
// whole dense grid give each cell's range of sorted particles. A query scans the H-mask cells
// around the particle's own cell (3^Dim cells for H = 1).
//
// The dense arrays cost 8 bytes per grid cell whether occupied or not, so a sparse set in a large box
// (one far outlier, say) would need far more memory than the particles themselves. Past
// max(2^22, 8 n) cells the grid wraps, as the CUDA sample's fixed-size grid does: cell c goes to slot
// (c_k mod w_k) per axis, with every w_k at least the mask's width 2R + 1. Distant cells then share a
// slot and their particles are rejected by the distance test; exactness holds because two cells of one
// mask never share a slot, and a particle in a shared slot that lies within h of the query would have
// its cell within R of the home cell on every axis, hence be in the slot's own cell.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <span>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/hmask.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"
#include "cellsph/neighbors/spatial_hash.hpp"  // CellFrame: the grid of eq. 15

namespace cellsph {

template <int Dim, class Real>
class SortedGrid {
 public:
  using Point = Vec<Dim, Real>;
  using Cell = typename CellFrame<Dim, Real>::Cell;

  // Dense grids up to max(2^22 cells (32 MiB of cellStart/cellEnd), 8 n); larger ones wrap.
  static constexpr double kDenseCells = 4194304.0;

  explicit SortedGrid(const SearchOptions& opt = {}) : subdivision_(opt.subdivision) {}

  void build(std::span<const Point> x, std::span<const Real> h) {
    const std::size_t n = x.size();
    frame_.build(x, h, subdivision_, "sorted-grid");
    mask_ = frame_.mask();
    int radius = 0;  // R: the mask's largest offset along any axis
    for (const MaskCell<Dim>& m : mask_)
      for (int k = 0; k < Dim; ++k) radius = std::max(radius, std::abs(m.offset[k]));
    double cells = 1.0;
    for (int k = 0; k < Dim; ++k) {
      wrap_[k] = frame_.dims[k];
      cells *= static_cast<double>(frame_.dims[k]);
    }
    const double limit = std::max(kDenseCells, 8.0 * static_cast<double>(n));
    wrapped_ = cells > limit;
    const std::int64_t narrowest = 2 * static_cast<std::int64_t>(radius) + 1;
    while (cells > limit) {
      const int k = static_cast<int>(std::max_element(wrap_.begin(), wrap_.end()) - wrap_.begin());
      if (wrap_[k] <= narrowest) break;  // (2R + 1)^Dim slots: never more than a few thousand
      cells /= static_cast<double>(wrap_[k]);
      wrap_[k] = std::max(wrap_[k] / 2, narrowest);
      cells *= static_cast<double>(wrap_[k]);
    }
    const auto num_cells = static_cast<std::size_t>(cells);
    for (int k = 0; k < Dim; ++k) stride_[k] = k == 0 ? 1 : stride_[k - 1] * wrap_[k - 1];

    // calcHash: key = (linear cell index << 32) | particle index, so sorting the keys sorts the
    // (hash, index) pairs by hash with ties in index order: the same order for any thread count.
    const auto count = static_cast<std::int64_t>(n);
    std::vector<std::uint64_t> keys(n);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < count; ++i) {
      const auto u = static_cast<std::size_t>(i);
      keys[u] = (linear(frame_.cell_of(x[u])) << 32) | static_cast<std::uint64_t>(u);
    }
    std::sort(keys.begin(), keys.end());

    // reorderDataAndFindCellStart: a cell starts where the hash differs from the previous one.
    index_.resize(n);
    xs_.resize(n);
    hs_.resize(n);
    cell_start_.assign(num_cells, kEmpty);
    cell_end_.assign(num_cells, kEmpty);
#pragma omp parallel for schedule(static)
    for (std::int64_t p = 0; p < count; ++p) {
      const auto u = static_cast<std::size_t>(p);
      const auto i = static_cast<std::uint32_t>(keys[u] & 0xffffffffU);
      const std::size_t cell = keys[u] >> 32;
      index_[u] = i;
      xs_[u] = x[i];
      hs_[u] = h[i];
      if (u == 0 || (keys[u - 1] >> 32) != cell) cell_start_[cell] = static_cast<std::uint32_t>(u);
      if (u + 1 == n || (keys[u + 1] >> 32) != cell) cell_end_[cell] = static_cast<std::uint32_t>(u + 1);
    }
  }

  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    const auto count = static_cast<std::int64_t>(index_.size());
    std::uint64_t tests = 0;
    // Particles are visited in sorted order: consecutive particles share their neighbour cells.
#pragma omp parallel for schedule(static) reduction(+ : tests)
    for (std::int64_t pp = 0; pp < count; ++pp) {
      const auto p = static_cast<std::uint32_t>(pp);
      const std::uint32_t i = index_[p];
      const Point xi = xs_[p];
      const Real hi2 = hs_[p] * hs_[p];
      const double reach = frame_.reach(hs_[p]);
      const Cell home = frame_.cell_of(xi);
      for (const MaskCell<Dim>& m : mask_) {
        if (!mask_keeps(m.gap2, reach)) continue;
        Cell c;
        for (int k = 0; k < Dim; ++k) c[k] = home[k] + m.offset[k];
        if (!frame_.inside(c)) continue;
        const std::size_t lin = linear(c);
        const std::uint32_t s = cell_start_[lin];
        if (s == kEmpty) continue;
        for (std::uint32_t q = s, e = cell_end_[lin]; q < e; ++q) {
          if (q == p) continue;
          ++tests;
          const Real r2 = distance2(xi, xs_[q]);
          if (r2 <= hi2) f(i, index_[q], r2);
        }
      }
    }
    return tests;
  }

  // True when the grid wraps (more cells than max(2^22, 8 n)): for tests and statistics.
  [[nodiscard]] bool wrapped() const {
    return wrapped_;
  }

  [[nodiscard]] std::size_t memory_bytes() const {
    return (cell_start_.capacity() + cell_end_.capacity() + index_.capacity()) * sizeof(std::uint32_t) +
           xs_.capacity() * sizeof(Point) + hs_.capacity() * sizeof(Real) +
           mask_.capacity() * sizeof(MaskCell<Dim>);
  }

 private:
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();

  // The slot of cell c: its linear index, or with a wrapped grid that of (c_k mod w_k).
  [[nodiscard]] std::uint64_t linear(const Cell& c) const {
    std::uint64_t v = 0;
    for (int k = 0; k < Dim; ++k) {
      const std::int64_t ck = wrapped_ ? c[k] % wrap_[k] : c[k];
      v += static_cast<std::uint64_t>(ck) * static_cast<std::uint64_t>(stride_[k]);
    }
    return v;
  }

  int subdivision_;
  CellFrame<Dim, Real> frame_;
  std::array<std::int64_t, Dim> stride_{};
  std::array<std::int64_t, Dim> wrap_{};  // slots per axis (the cells per axis unless wrapped_)
  bool wrapped_ = false;
  std::vector<MaskCell<Dim>> mask_;
  std::vector<std::uint32_t> cell_start_, cell_end_, index_;
  std::vector<Point> xs_;
  std::vector<Real> hs_;
};

}  // namespace cellsph
