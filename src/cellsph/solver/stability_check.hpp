#pragma once
// After each step: a fluid particle with a non-finite quantity, or outside the domain grown by one
// support, stops the run. The pass says whether particle i is bad; the driver reduces to the lowest such
// index (deterministic), and only then does host code describe it (the SimulationError's message).
#include <cmath>
#include <cstddef>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <int Dim, class Real>
struct StabilityCheckPass {
  ParticleView<Dim, Real> pv;
  bool escape;  // test the domain
  Vec<Dim, Real> lo, hi;
  Real margin;

  CELLSPH_HD bool operator()(std::size_t i) const {
    if (!all_finite(pv.x[i]) || !all_finite(pv.v[i]) || !all_finite(pv.f[i])) return true;
    if (!std::isfinite(pv.rho[i]) || !std::isfinite(pv.p[i])) return true;
    if (escape)
      for (int a = 0; a < Dim; ++a)
        if (pv.x[i][a] < lo[a] - margin || pv.x[i][a] > hi[a] + margin) return true;
    return false;
  }
};

}  // namespace cellsph
