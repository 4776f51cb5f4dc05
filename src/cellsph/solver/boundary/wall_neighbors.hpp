#pragma once
// The fluid neighbours of each wall particle, for the wall models that give wall particles a state of
// their own each step (adami2012.hpp, dynamic_crespo2007.hpp). A step searches boundary particles with
// support 0 (they have no rows), so the lists are gathered from the fluid rows (within h_f): counted,
// placed, then each wall's list sorted, so every sum over it runs in ascending fluid index whatever the
// thread count or the neighbour method (the set is exactly {f : |x_w - x_f| <= h_f}, the pairs the
// force passes see). Host code: the counting and placing use atomics (a device backend: atomicAdd and a
// segmented sort).
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

struct WallNeighbors {
  std::vector<std::uint32_t> start;  // n + 1 entries: row b is nbr[start[b]] .. nbr[start[b + 1]]
  std::vector<std::uint32_t> nbr;
  std::vector<std::uint32_t> cursor;  // scratch
};

template <int Dim, class Real>
void gather_wall_neighbors(const ParticleView<Dim, Real>& pv, const IndexSet& fluid, const IndexSet& boundary,
                           WallNeighbors& out) {
  const std::size_t n = pv.n;
  out.start.assign(n + 1, 0);
  auto each_wall_pair = [&](auto&& visit) {
    run_pass(fluid, [&](std::size_t f) {
      for (const auto* it = pv.row_begin(f); it != pv.row_end(f); ++it) {  // within h_f
        const std::uint32_t b = *it;
        if (pv.kind[b] == pv.kBoundary) visit(f, b);
      }
    });
  };
  each_wall_pair([&](std::size_t, std::uint32_t b) {
    std::atomic_ref<std::uint32_t>(out.start[b + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t i = 0; i < n; ++i) out.start[i + 1] += out.start[i];
  out.nbr.resize(out.start[n]);
  out.cursor.assign(out.start.begin(), out.start.end() - 1);
  each_wall_pair([&](std::size_t f, std::uint32_t b) {
    const std::uint32_t k =
        std::atomic_ref<std::uint32_t>(out.cursor[b]).fetch_add(1, std::memory_order_relaxed);
    out.nbr[k] = static_cast<std::uint32_t>(f);
  });
  run_pass(boundary, [&](std::size_t b) {
    std::sort(out.nbr.data() + out.start[b], out.nbr.data() + out.start[b + 1]);
  });
}

}  // namespace cellsph
