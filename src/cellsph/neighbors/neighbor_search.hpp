#pragma once
// One interface over every neighbour-search method. The method is chosen once at run time (a
// std::variant, dispatched once per traversal, never per particle); inside a traversal the visitor
// is inlined into the method's loop.
//
//   NeighborSearch<3, double> ns({.method = Method::CellIndex, .subdivision = 2});
//   ns.build(positions, support);           // per-particle support h_i
//   ns.find_all(list);                      // canonical CSR, rows sorted ascending
//   ns.for_each_pair([&](uint32_t i, uint32_t j, double r2) { ... });  // no list built
//
// Visitor contract: f(i, j, r2) is called once for every ordered pair with j in N(i); all calls
// for a given i come from one thread, one after the other (so accumulating into per-i arrays is
// race free). The order of j within a row is deterministic but method specific.
#include <span>
#include <variant>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/all_pairs.hpp"
#include "cellsph/neighbors/cell_index.hpp"
#include "cellsph/neighbors/csr_builder.hpp"
#include "cellsph/neighbors/kd_tree.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"
#include "cellsph/neighbors/sorted_grid.hpp"
#include "cellsph/neighbors/spatial_hash.hpp"

namespace cellsph {

template <int Dim, class Real>
class NeighborSearch {
 public:
  using Point = Vec<Dim, Real>;

  explicit NeighborSearch(SearchOptions opt = {}) : opt_(opt) { reset_impl(); }

  [[nodiscard]] const SearchOptions& options() const { return opt_; }
  void set_options(const SearchOptions& opt) {
    opt_ = opt;
    reset_impl();
  }

  // Builds the structure for positions x with one support length per particle (h.size() == n).
  // x must stay alive and unchanged until the last query of this build: all-pairs and a double
  // Cell Indexing search read it again.
  void build(std::span<const Point> x, std::span<const Real> h) {
    CELLSPH_CHECK(h.size() == x.size(), "support lengths " << h.size() << " != points " << x.size());
    n_ = x.size();
    Stopwatch sw;
    std::visit([&](auto& m) { m.build(x, h); }, impl_);
    stats_ = {};
    stats_.build_ms = sw.ms();
  }

  // Builds with one support length for all particles.
  // Builds with one support length for all particles. Methods that take it as is (Cell Indexing)
  // get no per-particle array.
  void build(std::span<const Point> x, Real radius) {
    if (auto* ci = std::get_if<CellIndex<Dim, Real>>(&impl_)) {
      uniform_h_ = {};
      n_ = x.size();
      Stopwatch sw;
      ci->build(x, radius);
      stats_ = {};
      stats_.build_ms = sw.ms();
      return;
    }
    uniform_h_.assign(x.size(), radius);
    build(x, std::span<const Real>(uniform_h_));
  }

  void find_all(NeighborList& out) {
    Stopwatch sw;
    // A method may provide its own CSR builder (same canonical output, faster); else the generic one.
    stats_.candidates = std::visit(
        [&](auto& m) -> std::uint64_t {
          if constexpr (requires { m.find_all(out); })
            return m.find_all(out);
          else
            return build_csr(m, n_, out);
        },
        impl_);
    stats_.query_ms = sw.ms();
    stats_.pairs = out.pairs();
    stats_.memory_bytes = structure_bytes() + out.memory_bytes();
  }

  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    return std::visit([&](const auto& m) { return m.for_each_pair(f); }, impl_);
  }

  [[nodiscard]] const SearchStats& stats() const { return stats_; }
  [[nodiscard]] std::size_t structure_bytes() const {
    return std::visit([](const auto& m) { return m.memory_bytes(); }, impl_) +
           uniform_h_.capacity() * sizeof(Real);
  }
  [[nodiscard]] std::size_t size() const { return n_; }

 private:
  void reset_impl() {
    switch (opt_.method) {
      case Method::AllPairs:
        impl_.template emplace<AllPairs<Dim, Real>>(opt_);
        break;
      case Method::SpatialHash:
        impl_.template emplace<SpatialHash<Dim, Real>>(opt_);
        break;
      case Method::CellIndex:
        impl_.template emplace<CellIndex<Dim, Real>>(opt_);
        break;
      case Method::SortedGrid:
        impl_.template emplace<SortedGrid<Dim, Real>>(opt_);
        break;
      case Method::KdTree:
        impl_.template emplace<KdTree<Dim, Real>>(opt_);
        break;
    }
  }

  SearchOptions opt_;
  std::variant<AllPairs<Dim, Real>, SpatialHash<Dim, Real>, CellIndex<Dim, Real>, SortedGrid<Dim, Real>,
               KdTree<Dim, Real>>
      impl_;
  std::vector<Real> uniform_h_;
  std::size_t n_ = 0;
  SearchStats stats_;
};

}  // namespace cellsph
