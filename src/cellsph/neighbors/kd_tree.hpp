#pragma once
// kd-tree through nanoflann (Debian 1.4.3): the hierarchical method the paper leaves to future
// work (section 6). One radius query per particle, with that particle's own support h_i.
//
// Exactness: nanoflann 1.4.3 accepts a point only when its squared distance is strictly below the
// query radius (`dist < radius` in RadiusResultSet and in the leaf scan), and it computes distances
// in its own order of operations. So each query asks for a slightly larger squared radius and every
// point returned is re-tested with exactly the reference expression distance2(x_i, x_j) <= h_i^2.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <omp.h>
#include <nanoflann.hpp>

#include "cellsph/core/error.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

namespace detail {

// Distance evaluations of the calling thread, so queries can report their candidates.
inline thread_local std::uint64_t kd_distance_tests = 0;

template <int Dim, class Real>
struct KdPoints {
  std::span<const Vec<Dim, Real>> x;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return x.size(); }
  [[nodiscard]] Real kdtree_get_pt(std::uint32_t i, std::size_t k) const { return x[i][static_cast<int>(k)]; }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;  // let nanoflann compute it
  }
};

// nanoflann's L2_Simple_Adaptor with a counter of leaf distance evaluations.
template <int Dim, class Real>
struct CountingL2 {
  using ElementType = Real;
  using DistanceType = Real;
  const KdPoints<Dim, Real>& points;
  explicit CountingL2(const KdPoints<Dim, Real>& p) : points(p) {}

  Real evalMetric(const Real* a, std::uint32_t b, std::size_t size) const {
    ++kd_distance_tests;
    Real s = 0;
    for (std::size_t k = 0; k < size; ++k) {
      const Real d = a[k] - points.kdtree_get_pt(b, k);
      s += d * d;
    }
    return s;
  }
  template <class U, class V>
  Real accum_dist(const U a, const V b, std::size_t /*dim*/) const {
    return (a - b) * (a - b);
  }
};

// Collects the indices nanoflann accepts; the exact test happens afterwards.
template <class Real>
struct KdCollector {
  Real radius;
  std::vector<std::uint32_t>* out;
  void init() { out->clear(); }
  [[nodiscard]] std::size_t size() const { return out->size(); }
  [[nodiscard]] bool full() const { return true; }
  bool addPoint(Real /*dist*/, std::uint32_t index) {
    out->push_back(index);
    return true;
  }
  [[nodiscard]] Real worstDist() const { return radius; }
};

}  // namespace detail

template <int Dim, class Real>
class KdTree {
 public:
  using Point = Vec<Dim, Real>;

  // Leaf size of the tree (nanoflann's default is 10); 16 trades a few more distance tests for a
  // shallower tree.
  static constexpr std::size_t kLeafSize = 16;
  // Relative enlargement of the squared query radius: far above the few ulps by which nanoflann's
  // distance can differ from distance2(), far below one lattice spacing.
  static constexpr double kRadiusSlack = 1.0 / 1024.0;

  explicit KdTree(const SearchOptions& /*opt*/ = {}) {}

  void build(std::span<const Point> x, std::span<const Real> h) {
    CELLSPH_CHECK(x.size() < std::numeric_limits<std::uint32_t>::max(),
                  "kd-tree: " << x.size() << " points exceed 32-bit indices");
    for (std::size_t i = 0; i < x.size(); ++i) {
      CELLSPH_CHECK(all_finite(x[i]), "kd-tree: point " << i << " has a non-finite coordinate");
      CELLSPH_CHECK(std::isfinite(h[i]) && h[i] >= Real(0),
                    "kd-tree: support length h[" << i << "] = " << h[i] << " is not finite and >= 0");
    }
    index_.reset();
    points_ = std::make_unique<detail::KdPoints<Dim, Real>>(detail::KdPoints<Dim, Real>{x});
    h_ = h;
    if (!x.empty())
      index_ = std::make_unique<Index>(Dim, *points_, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
  }

  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    if (!index_) return 0;
    const std::span<const Point> x = points_->x;
    const auto count = static_cast<std::int64_t>(x.size());
    std::uint64_t tests = 0;
#pragma omp parallel reduction(+ : tests)
    {
      std::vector<std::uint32_t> found;
      const std::uint64_t before = detail::kd_distance_tests;
      const nanoflann::SearchParams params(32, 0.0F, false);
#pragma omp for schedule(static)
      for (std::int64_t ii = 0; ii < count; ++ii) {
        const auto i = static_cast<std::uint32_t>(ii);
        const Point xi = x[i];
        const Real hi2 = h_[i] * h_[i];
        if (!std::isfinite(hi2)) {  // h^2 overflows: every point passes distance2 <= inf
          for (std::uint32_t j = 0; j < x.size(); ++j)
            if (j != i) f(i, j, distance2(xi, x[j]));
          tests += x.size() - 1;
          continue;
        }
        // Enlarged radius; nextafter keeps it positive when h_i = 0 so duplicates are still found.
        const Real query = std::nextafter(static_cast<Real>(hi2 * static_cast<Real>(1.0 + kRadiusSlack)),
                                          std::numeric_limits<Real>::infinity());
        detail::KdCollector<Real> collect{query, &found};
        collect.init();
        index_->findNeighbors(collect, xi.c, params);
        for (const std::uint32_t j : found) {
          if (j == i) continue;
          const Real r2 = distance2(xi, x[j]);
          if (r2 <= hi2) f(i, j, r2);
        }
      }
      tests += detail::kd_distance_tests - before;
    }
    return tests;
  }

  [[nodiscard]] std::size_t memory_bytes() const {
    return index_ ? index_->usedMemory(*index_) : 0;
  }

 private:
  using Index = nanoflann::KDTreeSingleIndexAdaptor<detail::CountingL2<Dim, Real>,
                                                    detail::KdPoints<Dim, Real>, Dim, std::uint32_t>;
  std::unique_ptr<detail::KdPoints<Dim, Real>> points_;
  std::unique_ptr<Index> index_;
  std::span<const Real> h_;
};

}  // namespace cellsph
