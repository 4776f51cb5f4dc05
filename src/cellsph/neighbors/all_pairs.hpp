#pragma once
// All-pairs: the O(n^2) reference every other method is tested against.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

template <int Dim, class Real>
class AllPairs {
 public:
  explicit AllPairs(const SearchOptions& /*opt*/ = {}) {}

  void build(std::span<const Vec<Dim, Real>> x, std::span<const Real> h) {
    x_ = x;
    h_ = h;
  }

  // Calls f(i, j, r2) for every ordered pair with j in N(i). All calls for one i happen on one
  // thread, one after the other. Returns the number of distance tests.
  template <class F>
  std::uint64_t for_each_pair(F&& f) const {
    const std::size_t n = x_.size();
    parallel_for(n, [&](std::size_t i) {
      const auto xi = x_[i];
      const Real hi2 = h_[i] * h_[i];
      for (std::size_t j = 0; j < n; ++j) {
        if (j == i) continue;
        const Real r2 = distance2(xi, x_[j]);
        if (r2 <= hi2) f(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), r2);
      }
    });
    return static_cast<std::uint64_t>(n) * (n > 0 ? n - 1 : 0);
  }

  [[nodiscard]] std::size_t memory_bytes() const { return 0; }

 private:
  std::span<const Vec<Dim, Real>> x_;
  std::span<const Real> h_;
};

}  // namespace cellsph
