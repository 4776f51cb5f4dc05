#pragma once
// The per-particle passes of the Verlet lists (the lists hold the pairs within h + skin of the positions
// they were built from, see simulation.hpp):
//  * MaxDisplacementPass: the largest squared displacement since the build (a reduction), which
//    decides whether the lists still hold every pair within h;
//  * FilterRowsPass: each row cut to the pairs within h_i, in the same (ascending) order, so every pair
//    pass then runs without the skin test. That test is a branch taken for about a third of the
//    candidates; once the particles are in cell order (reorder_every) its pattern along a sorted row is
//    irregular, and the mispredictions cost more than this pass (which writes each candidate and
//    advances by the test's outcome, without a branch). The test is the one the pair loops made before:
//    the same pairs, the same bits.
//  * RowLengthPass: the cut of rows that a search at h itself gave (no skin): every candidate is within
//    h_i by the search's own test, which is this pass's (distance2(x_i, x_j) <= h_i^2, exactly: the
//    searches decide by it in float and double alike), so the rows are the candidates and only their
//    lengths are written.
#include <algorithm>
#include <cstddef>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <class Real>
struct MaxValue {
  Real value = 0;
  CELLSPH_HD static MaxValue max_of(const MaxValue& a, const MaxValue& b) {
    return {std::max(a.value, b.value)};
  }
};

template <int Dim, class Real>
struct MaxDisplacementPass {
  ParticleView<Dim, Real> pv;
  const Vec<Dim, Real>* x_built;

  CELLSPH_HD MaxValue<Real> operator()(std::size_t i) const { return {distance2(pv.x[i], x_built[i])}; }
};

template <int Dim, class Real>
struct FilterRowsPass {
  ParticleView<Dim, Real> pv;
  std::uint32_t* within;  // the cut rows, at the candidates' offsets

  CELLSPH_HD void operator()(std::size_t i) const {
    const Vec<Dim, Real> xi = pv.x[i];
    const Real hi2 = pv.h[i] * pv.h[i];
    std::uint32_t* out = within + pv.offsets[i];
    std::uint32_t c = 0;
    for (const auto* it = pv.candidates_begin(i); it != pv.candidates_end(i); ++it) {
      const std::uint32_t j = *it;
      out[c] = j;
      c += distance2(xi, pv.x[j]) <= hi2 ? 1u : 0u;
    }
    pv.within_count[i] = c;
  }
};

template <int Dim, class Real>
struct RowLengthPass {
  ParticleView<Dim, Real> pv;

  CELLSPH_HD void operator()(std::size_t i) const {
    pv.within_count[i] = static_cast<std::uint32_t>(pv.offsets[i + 1] - pv.offsets[i]);
  }
};

}  // namespace cellsph
