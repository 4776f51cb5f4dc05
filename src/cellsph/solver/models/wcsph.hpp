#pragma once
// The CUDA write-up's weakly compressible SPH (Model::Wcsph):
//  * density: summation_density.hpp (mass density, then the equation of state);
//    or the continuity equation with density diffusion: continuity_density.hpp (solver.density);
//  * forces, kept apart so that the integrator can apply them in two sub-steps: the non-pressure forces
//    (the laminar viscosity of Morris et al. 1997 with each phase's mu, Monaghan's artificial viscosity
//    when alpha > 0, gravity, Mueller 2003 surface tension) in f, the symmetric pressure force in
//    f_pressure: WcsphForcesPass. Walls: the laminar term only with slip = no-slip (against the wall's
//    velocity: at rest, or Adami's extrapolated one), the artificial one only with
//    artificial_viscosity.walls;
//  * operator splitting with symplectic Euler: WcsphSymplecticEulerPass.
// The pair formulas are in physics/interactions.hpp; wall particles enter as the boundary model says
// (boundary/).
#include <cstddef>
#include <type_traits>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/boundary/akinci2012.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/continuity_density.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

template <int Dim, class Real, class GradKernel>
struct WcsphForcesPass {
  ParticleView<Dim, Real> pv;
  GradKernel wg;  // the pressure kernel: its gradient serves pressure and both viscosities
  Poly6Kernel<Dim, Real> wc;
  Vec<Dim, Real> gravity;
  Real lap_self;  // wc.laplacian(0)
  Real eta2;      // the r^2 regulariser 0.01 h_s^2 (h_s = support / 2, the smoothing length)
  Real tension_threshold;
  Real alpha_c0_h;   // artificial viscosity alpha c0 h_s; 0: none
  bool av_walls;     // artificial viscosity between fluid and wall particles too
  bool any_tension;  // some phase has sigma > 0
  bool wall_states;  // Adami or dynamic walls: wall particles carry p, rho, vol, prho2 and wall_v
  bool no_slip;
  bool clamp_negative;  // the EOS's, for Akinci walls' mirrored pressure

  // The force fluid particle i feels from wall particle j (x_ij = x_i - x_j, r = |x_ij|, g = grad W(x_ij)),
  // added to fp (pressure) and fnp (the rest). Written once: the fluid's force pass adds it to i, the
  // floating bodies' force pass (boundary/rigid_bodies.hpp) subtracts it from j with the same bits.
  CELLSPH_HD void wall_pair(std::size_t i, std::uint32_t j, const Vec<Dim, Real>& xij, Real r,
                            const Vec<Dim, Real>& g, Vec<Dim, Real>& fp, Vec<Dim, Real>& fnp) const {
    using V = Vec<Dim, Real>;
    const Real mi = pv.m[i], rhoi = pv.rho[i], pi = pv.p[i], mui = pv.mu[i];
    const Real vol_i = mi / rhoi;
    const V vel_i = pv.v[i];
    const bool laminar = mui > 0;
    if (wall_states) {
      // Adami / dynamic walls: the fluid pair terms with the wall's pressure, density and velocity
      // (boundary/adami2012.hpp, boundary/dynamic_crespo2007.hpp); the laminar viscosity takes i's mu
      // and the wall's no-slip velocity, the artificial one the wall's own (its prescribed velocity).
      fp += symmetric_pressure_force(g, mi, pv.m[j], pv.prho2[i], pv.prho2[j]);
      if (no_slip && laminar)
        fnp +=
            morris_viscosity_force(V(vel_i - pv.wall_v[j]), g, xij, r * r, vol_i, pv.vol[j], mui, mui, eta2);
      if (av_walls && alpha_c0_h > 0)
        fnp += artificial_viscosity_force(V(vel_i - pv.v[j]), g, xij, r, mi, pv.m[j], rhoi, pv.rho[j],
                                          alpha_c0_h, eta2);
    } else {
      // Akinci walls (boundary/akinci2012.hpp): mirrored density, extrapolated pressure; no slip:
      // the laminar operator against the wall particle's velocity (0 at rest, boundary/wall_motion.hpp)
      // with volume psi_b / rho_i and i's mu.
      const Real pb = akinci2012_wall_pressure(pi, rhoi, gravity, xij, clamp_negative);
      fp += boundary_pressure_force(g, mi, rhoi, pi, pb, pv.m[j]);
      if (no_slip && laminar)
        fnp +=
            morris_viscosity_force(V(vel_i - pv.v[j]), g, xij, r * r, vol_i, pv.m[j] / rhoi, mui, mui, eta2);
      if (av_walls && alpha_c0_h > 0)
        fnp += artificial_viscosity_force(V(vel_i - pv.v[j]), g, xij, r, mi, pv.m[j], rhoi, rhoi, alpha_c0_h,
                                          eta2);
    }
  }

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const Real vol_i = pv.m[i] / pv.rho[i];
    V fnp = gravity * pv.m[i];
    V fp{};
    ColorField<Dim, Real> cf;
    cf.lap = vol_i * lap_self;
    const Real mi = pv.m[i], rhoi = pv.rho[i], mui = pv.mu[i];
    const V vel_i = pv.v[i];
    const Real prho2_i = pv.prho2[i];
    const bool laminar = mui > 0;
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
      const std::uint32_t j = *it;
      const V xij = pv.x[i] - pv.x[j];
      const Real r = norm(xij);
      const V g = wg.gradW(xij);  // one kernel gradient per pair, shared by the terms
      if (pv.is_fluid(j)) {
        const V vij = vel_i - pv.v[j];
        if (laminar || pv.mu[j] > 0)
          fnp += morris_viscosity_force(vij, g, xij, r * r, vol_i, pv.vol[j], mui, pv.mu[j], eta2);
        if (alpha_c0_h > 0)
          fnp += artificial_viscosity_force(vij, g, xij, r, mi, pv.m[j], rhoi, pv.rho[j], alpha_c0_h, eta2);
        fp += symmetric_pressure_force(g, mi, pv.m[j], prho2_i, pv.prho2[j]);
        if (any_tension) accumulate_color(cf, xij, r, pv.vol[j], Real(1), wc);
      } else {
        // Walls: wall_pair (the floating bodies' reaction reads the same expression).
        wall_pair(i, j, xij, r, g, fp, fnp);
        if (any_tension) accumulate_color(cf, xij, r, pv.m[j] / rhoi, Real(1), wc);
      }
    }
    if (any_tension) {
      // Mueller 2003 gives a force density; the particle's share is V_i times it.
      fnp += interface_tension_force(cf, pv.phase_of(i).sigma, tension_threshold) * vol_i;
    }
    pv.f[i] = fnp;
    pv.f_pressure[i] = fp;
  }
};

// The write-up's split: v* = v + dt (F_visc + F_ext)/m, then v(t+dt) = v* + dt F_press/m,
// x(t+dt) = x + dt v(t+dt) (symplectic Euler). f becomes the total force, for output and the force
// limit of the next step.
template <int Dim, class Real>
struct WcsphSymplecticEulerPass {
  ParticleView<Dim, Real> pv;
  Real dt;

  CELLSPH_HD void operator()(std::size_t i) const {
    const Vec<Dim, Real> vstar = pv.v[i] + pv.f[i] * (dt / pv.m[i]);
    pv.v[i] = vstar + pv.f_pressure[i] * (dt / pv.m[i]);
    pv.x[i] += pv.v[i] * dt;
    pv.f[i] += pv.f_pressure[i];
  }
};

// The same step in two halves, for the continuity density (continuity_density.hpp), whose rate is taken
// between them: with the new velocities at the old positions, so that density and velocity form a symplectic
// Euler pair (rates from the old velocities would make the acoustic oscillation a forward-Euler one, which
// grows every step: a 2D dam break blew up within 200 steps that way).
template <int Dim, class Real>
struct WcsphKickPass {
  ParticleView<Dim, Real> pv;
  Real dt;

  CELLSPH_HD void operator()(std::size_t i) const {
    const Vec<Dim, Real> vstar = pv.v[i] + pv.f[i] * (dt / pv.m[i]);
    pv.v[i] = vstar + pv.f_pressure[i] * (dt / pv.m[i]);
    pv.f[i] += pv.f_pressure[i];
  }
};

template <int Dim, class Real>
struct WcsphDriftPass {
  ParticleView<Dim, Real> pv;
  Real dt;

  CELLSPH_HD void operator()(std::size_t i) const { pv.x[i] += pv.v[i] * dt; }
};

// The force pass of this config, handed to `fn` (wcsph_forces runs it; the floating bodies call its
// wall_pair).
template <int Dim, class Real, class F>
void with_wcsph_forces_pass(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                            bool any_tension, bool wall_states, F&& fn) {
  const Poly6Kernel<Dim, Real> wc(cfg.support);
  const Real h = smoothing_length(cfg);
  const Real alpha_c0_h = cfg.artificial_viscosity.alpha * reference_sound_speed(cfg) * h;
  with_kernel<Dim, Real>(cfg.pressure_kernel, cfg.support, [&](const auto wg) {
    using K = std::remove_cvref_t<decltype(wg)>;
    fn(WcsphForcesPass<Dim, Real, K>{pv, wg, wc, cfg.gravity, wc.laplacian(0), Real(0.01) * h * h,
                                     cfg.tension_threshold, alpha_c0_h, cfg.artificial_viscosity.walls,
                                     any_tension, wall_states, cfg.no_slip, cfg.eos.clamp_negative});
  });
}

// The forces of `set` (the fluid), after the densities and the wall states.
template <int Dim, class Real, class Set>
void wcsph_forces(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& set,
                  bool any_tension, bool wall_states) {
  with_wcsph_forces_pass(cfg, pv, any_tension, wall_states, [&](const auto& pass) { run_pass(set, pass); });
}

}  // namespace cellsph
