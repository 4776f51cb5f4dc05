#pragma once
// The WCSPH model's continuity-equation density (SolverConfig::density_evolution = Continuity, scene key
// solver.density = "continuity"), with optional density diffusion (delta-SPH):
//  * ContinuityStatePass: the equation of state of the carried density (p, V = m / rho, p / rho^2), in place
//    of the summation pass; the densities are state, carried by Particles::rho (and so by checkpoints);
//  * ContinuityRatePass: d rho_i / dt = sum_j m_j (v_i - v_j) . grad W_ij over every neighbour (walls with
//    their weights m_b and velocities, the same pairs as the summation: it is that sum's time derivative),
//    plus delta h c0 lap(rho) between fluid particles of one phase (Molteni & Colagrossi 2009, or Fourtakas
//    et al. 2019 on the density less its hydrostatic part);
//  * ContinuityIntegratePass: rho += dt d rho / dt. The step (Simulation::integrate_wcsph): the kick
//    v += dt f / m (forces from the old densities), the rate with the new velocities at the old positions,
//    the density update, the drift x += dt v: symplectic Euler for the pair (rho, v), as for (x, v).
// Density diffusion acts between fluid particles only, whatever the wall model: Akinci walls mirror the fluid
// particle's density (the term would be 0), Adami and dynamic walls get a density each step from their
// fluid neighbours (never integrated), so diffusing into them would only move the fluid's density towards a
// value derived from itself; and the kernel truncated at a wall is where the Laplacian's error is largest.
// The pair formulas are in physics/interactions.hpp; the kernel is the density kernel (the summation's).
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

template <int Dim, class Real>
struct ContinuityStatePass {
  ParticleView<Dim, Real> pv;
  EquationOfState<Real> eos;

  CELLSPH_HD void operator()(std::size_t i) const {
    const Real rho = pv.rho[i];
    const Real pres = eos.pressure(rho, pv.rho0[i]);
    pv.p[i] = pres;
    pv.vol[i] = pv.m[i] / rho;
    pv.prho2[i] = pres / (rho * rho);
  }
};

template <int Dim, class Real, class Kernel>
struct ContinuityRatePass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel
  EquationOfState<Real> eos;
  Vec<Dim, Real> gravity;
  Real delta_h_c0;   // 0: no diffusion
  Real eta2;         // 0.01 h^2
  bool hydrostatic;  // Fourtakas: subtract the hydrostatic density difference

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const V xi = pv.x[i], vi = pv.v[i];
    const Real rhoi = pv.rho[i], rho0i = pv.rho0[i];
    const std::int32_t phi = pv.phase[i];
    Real rate = 0, diffusion = 0;
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
      const std::uint32_t j = *it;
      const V xij = xi - pv.x[j];
      const V g = w.gradW(xij);
      rate += continuity_term(g, pv.m[j], vi - pv.v[j]);
      if (delta_h_c0 > 0 && pv.is_fluid(j) && pv.phase[j] == phi) {
        const Real fij = brookshaw_weight(g, xij, norm(xij), pv.vol[j], eta2);
        const Real drho_h = hydrostatic ? hydrostatic_density_difference(eos, rho0i, gravity, xij) : Real(0);
        diffusion += density_diffusion_term(delta_h_c0, rhoi, pv.rho[j], drho_h, fij);
      }
    }
    pv.drho[i] = rate + diffusion;
  }
};

template <int Dim, class Real>
struct ContinuityIntegratePass {
  ParticleView<Dim, Real> pv;
  Real dt;

  CELLSPH_HD void operator()(std::size_t i) const { pv.rho[i] += dt * pv.drho[i]; }
};

// Pressures of `set` (the fluid) from their carried densities.
template <int Dim, class Real, class Set>
void continuity_state(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& set) {
  run_pass(set, ContinuityStatePass<Dim, Real>{pv, cfg.eos});
}

// The smoothing length of the diffusion and artificial-viscosity terms: half the kernel support (the h of
// the cubic spline's and Wendland's support 2h, in which delta and alpha are quoted in the literature).
template <int Dim, class Real>
Real smoothing_length(const SolverConfig<Dim, Real>& cfg) {
  return cfg.support / 2;
}

// The speed of sound of those terms: at the smallest rest density (as the Courant step's).
template <int Dim, class Real>
Real reference_sound_speed(const SolverConfig<Dim, Real>& cfg) {
  Real rho0 = cfg.phases.front().rest_density;
  for (const auto& ph : cfg.phases) rho0 = ph.rest_density < rho0 ? ph.rest_density : rho0;
  return cfg.eos.sound_speed(rho0);
}

// d rho / dt of `set` (the fluid), after the kick (models/wcsph.hpp), before the drift.
template <int Dim, class Real, class Set>
void continuity_rate(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& set) {
  const Real h = smoothing_length(cfg);
  const auto kind = cfg.density_diffusion.kind;
  const Real dhc =
      kind == DensityDiffusion::None ? Real(0) : cfg.density_diffusion.delta * h * reference_sound_speed(cfg);
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    using K = std::remove_cvref_t<decltype(w)>;
    run_pass(set, ContinuityRatePass<Dim, Real, K>{pv, w, cfg.eos, cfg.gravity, dhc, Real(0.01) * h * h,
                                                   kind == DensityDiffusion::Fourtakas});
  });
}

}  // namespace cellsph
