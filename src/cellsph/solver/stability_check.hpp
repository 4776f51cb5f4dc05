#pragma once
// After each step: a fluid particle with a non-finite quantity, a density that is not positive (a
// continuity density driven through zero by a particle squeezed between wall layers: SPHERIC Test 2 with
// Fourtakas diffusion went 529 -> 2824 -> -827 kg/m^3 before the particle left), a speed or acceleration
// whose square overflows (a Courant step of 0), or outside the domain
// grown by one support, stops the run. The pass says whether particle i is bad; the driver reduces to the
// lowest such index (deterministic), and only then does host code describe it (the SimulationError's
// message).
#include <cmath>
#include <cstddef>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/config.hpp"
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
    // A speed or an acceleration whose square overflows Real: the Courant step (timestep/global_courant.hpp)
    // would be 0, and the run would not advance.
    if (!std::isfinite(norm2(pv.v[i])) || !std::isfinite(norm2(pv.f[i]) / (pv.m[i] * pv.m[i]))) return true;
    if (!std::isfinite(pv.rho[i]) || !std::isfinite(pv.p[i]) || !(pv.rho[i] > 0)) return true;
    if (escape)
      for (int a = 0; a < Dim; ++a)
        if (pv.x[i][a] < lo[a] - margin || pv.x[i][a] > hi[a] + margin) return true;
    return false;
  }
};

// The check's domain: the scene's domain if set, else the box if enabled, else none (escape false);
// margin one support.
template <int Dim, class Real>
StabilityCheckPass<Dim, Real> stability_check(const SolverConfig<Dim, Real>& cfg,
                                              const ParticleView<Dim, Real>& pv) {
  StabilityCheckPass<Dim, Real> c{pv, false, {}, {}, cfg.support};
  if (cfg.domain_set) {
    c.lo = cfg.domain_lo;
    c.hi = cfg.domain_hi;
    c.escape = true;
  } else if (cfg.box.enabled) {
    c.lo = cfg.box.lo;
    c.hi = cfg.box.hi;
    c.escape = true;
  }
  return c;
}

}  // namespace cellsph
