#pragma once
// Dynamic boundary particles (Crespo, Gomez-Gesteira & Dalrymple 2007; WallModel::Dynamic), with
// summation density: each wall particle is a fluid particle held at rest. Its density is the sum over
// its wall neighbours (fixed for the run: DynamicWallSelfDensityPass, once) and its fluid neighbours
// (each step: DynamicWallStatePass, over the lists of wall_neighbors.hpp); its pressure the fluid's
// equation of state, never below 0. The pair forces are the fluid's (models/), so the forces are minus
// the gradient of the total internal energy and the walls do no net work.
#include <algorithm>
#include <cstddef>
#include <type_traits>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/eos.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// sum_c m_c W_wc over the wall particles c within h of wall w (w itself included), in row order
// (ascending). Run over all particles with the exact rows of every particle (candidates rows, searched
// at h), after the weights (a neighbour's weight may just have been set).
template <int Dim, class Real, class Kernel>
struct DynamicWallSelfDensityPass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel

  CELLSPH_HD void operator()(std::size_t b) const {
    if (pv.kind[b] != pv.kBoundary) return;
    Real s = pv.m[b] * w.W2(0);
    for (const auto* it = pv.candidates_begin(b); it != pv.candidates_end(b); ++it)
      if (pv.kind[*it] == pv.kBoundary) s += pv.m[*it] * w.W2(distance2(pv.x[b], pv.x[*it]));
    pv.wall_self_rho[b] = s;
  }
};

// Run over the boundary particles after the density pass; writes p, rho, vol, prho2 and wall_v of b.
template <int Dim, class Real, class Kernel>
struct DynamicWallStatePass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel
  EquationOfState<Real> eos;

  CELLSPH_HD void operator()(std::size_t b) const {
    const std::uint32_t* first = pv.wall_nbr + pv.wall_start[b];
    const std::uint32_t* last = pv.wall_nbr + pv.wall_start[b + 1];
    // Summation density (its fixed wall part, then the fluid in ascending index) and the fluid's EOS,
    // never below 0: the outer layers lack neighbours beyond them, and an unclamped EOS would make them
    // pull the fluid in. Any p_w(rho_w) is the derivative of a wall energy (here the clamped EOS's), so
    // the forces stay conservative.
    Real rho = pv.wall_self_rho[b];
    for (const std::uint32_t* it = first; it != last; ++it)
      rho += density_term(w, pv.m[*it], distance2(pv.x[b], pv.x[*it]));
    const Real pw = std::max(Real(0), eos.pressure(rho, pv.rho0[b]));
    pv.p[b] = pw;
    pv.rho[b] = rho;
    pv.vol[b] = pv.m[b] / rho;
    pv.prho2[b] = pw / (rho * rho);
    pv.wall_v[b] = pv.v[b];
  }
};

// Each wall's fixed wall-wall density (pv.wall_self_rho sized for every particle), after the weights.
template <int Dim, class Real>
void dynamic_wall_self_density(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv) {
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    run_pass(pv.n, DynamicWallSelfDensityPass<Dim, Real, std::remove_cvref_t<decltype(w)>>{pv, w});
  });
}

// The states of the wall particles of `boundary`, after the density pass and gather_wall_neighbors.
template <int Dim, class Real, class Set>
void dynamic_wall_states(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                         const Set& boundary) {
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    run_pass(boundary, DynamicWallStatePass<Dim, Real, std::remove_cvref_t<decltype(w)>>{pv, w, cfg.eos});
  });
}

}  // namespace cellsph
