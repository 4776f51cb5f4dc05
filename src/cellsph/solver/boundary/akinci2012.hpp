#pragma once
// Boundary particles after Akinci et al. 2012 (WallModel::Akinci, the default): each wall particle b
// carries a "volume mass" psi_b = rho0 V_b with V_b = 1 / sum_k W_bk over the boundary particles (itself
// included), so that an irregularly sampled wall still adds the same density per unit area. In the
// force passes a wall particle takes, per pair, the fluid particle's density (mirrored) and its pressure
// extrapolated hydrostatically (akinci2012_wall_pressure); the pair formulas are in
// physics/interactions.hpp, called from the model files (models/).
#include <cstddef>
#include <type_traits>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// psi_b of every boundary particle b with no weight given by the scene (m_b == 0). Run over all
// particles with the exact neighbour rows of every particle (candidates rows, searched at h).
template <int Dim, class Real, class Kernel>
struct Akinci2012WeightPass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel

  CELLSPH_HD void operator()(std::size_t b) const {
    if (pv.kind[b] != pv.kBoundary || pv.m[b] > 0) return;  // a weight given by the scene is kept
    Real s = w.W2(0);
    for (const auto* it = pv.candidates_begin(b); it != pv.candidates_end(b); ++it)
      if (pv.kind[*it] == pv.kBoundary) s += w.W2(distance2(pv.x[b], pv.x[*it]));
    pv.m[b] = pv.rho0[b] / s;
  }
};

// The pressure a wall particle has for fluid particle i (x_ij = x_i - x_b): i's, extrapolated
// hydrostatically, and never below 0 where the equation of state clamps.
template <int Dim, class Real>
CELLSPH_HD inline Real akinci2012_wall_pressure(Real pi, Real rhoi, const Vec<Dim, Real>& g,
                                                const Vec<Dim, Real>& xij, bool clamp_negative) {
  Real pb = mirrored_boundary_pressure(pi, rhoi, g, xij);
  if (clamp_negative && pb < 0) pb = 0;
  return pb;
}

// psi_b of every boundary particle without a given weight (pv's candidate rows: a search at h with rows
// for every particle).
template <int Dim, class Real>
void akinci2012_weights(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv) {
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    run_pass(pv.n, Akinci2012WeightPass<Dim, Real, std::remove_cvref_t<decltype(w)>>{pv, w});
  });
}

}  // namespace cellsph
