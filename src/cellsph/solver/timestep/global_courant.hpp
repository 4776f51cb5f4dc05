#pragma once
// Global time steps (TimeStepping::Fixed and Courant): one dt for every particle, chosen each step.
// Courant: eq. 12 (alpha h / c and alpha h / |v|), the viscous limit viscous * h^2 / nu and the force
// limit force * sqrt(h / |a|), capped at dt_max. The particle maxima |v|^2 and |a|^2 are a reduction
// pass (CourantLimitsPass), the rest is host arithmetic on the phase table.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

template <class Real>
struct CourantMaxima {
  Real v2 = 0;  // max |v|^2
  Real a2 = 0;  // max |a|^2
  CELLSPH_HD static CourantMaxima max_of(const CourantMaxima& a, const CourantMaxima& b) {
    return {std::max(a.v2, b.v2), std::max(a.a2, b.a2)};
  }
};

template <int Dim, class Real>
struct CourantLimitsPass {
  ParticleView<Dim, Real> pv;
  bool split_pressure;  // WCSPH: the total force is f + f_pressure

  CELLSPH_HD CourantMaxima<Real> operator()(std::size_t i) const {
    const Vec<Dim, Real> f = split_pressure ? pv.f[i] + pv.f_pressure[i] : pv.f[i];
    return {norm2(pv.v[i]), norm2(f) / (pv.m[i] * pv.m[i])};
  }
};

// The step of a global-step scheme over the particles of `set` (the fluid).
template <int Dim, class Real, class Set>
Real global_courant_dt(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                       const Set& set) {
  if (cfg.time.mode == TimeStepping::Fixed) return cfg.time.dt;
  const Real h = cfg.support;
  const Real alpha = cfg.time.courant;
  Real dt = cfg.time.dt_max;
  Real rho0_min = std::numeric_limits<Real>::max(), nu_max = 0;
  for (const auto& ph : cfg.phases) {
    rho0_min = std::min(rho0_min, ph.rest_density);
    nu_max = std::max(nu_max, ph.viscosity / ph.rest_density);
  }
  dt = std::min(dt, alpha * h / cfg.eos.sound_speed(rho0_min));
  if (nu_max > 0) dt = std::min(dt, cfg.time.viscous * h * h / nu_max);
  const auto mx =
      reduce_max(set, CourantMaxima<Real>{}, CourantLimitsPass<Dim, Real>{pv, cfg.model == Model::Wcsph});
  if (mx.v2 > 0) dt = std::min(dt, alpha * h / std::sqrt(mx.v2));
  if (mx.a2 > 0) dt = std::min(dt, cfg.time.force * std::sqrt(h / std::sqrt(mx.a2)));
  return dt;
}

}  // namespace cellsph
