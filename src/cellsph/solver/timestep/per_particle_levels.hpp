#pragma once
// Per-particle power-of-two steps (Desbrun 1996; paper eq. 12-13; TimeStepping::PerParticle, paper model).
// Times are integer ticks of dt_max / 2^max_level, so "is particle i due" is an exact comparison. A step:
//  1. the global clock T is the smallest particle time (earliest_tick); particles with tick == T are due;
//  2. every position is extrapolated to T (ExtrapolatePass); forces are evaluated for the due particles
//     only, densities (and CSF normals) only where those forces read them (build_work_sets), so a
//     sub-step costs in proportion to the particles it advances;
//  3. a due particle picks its level from eq. 12 (coarsening only onto a multiple of the coarser step),
//     gets the position correction of a step change, then the leap-frog kick and drift of Algorithm 1
//     (PerParticleLevelPass).
// Step change: the stored v = v(t - dt_old/2) must become v(t + dt_new/2) = v + a (dt_old + dt_new)/2
// (Exact). Algorithm 1's kick v += a dt_new leaves the velocity off by a (dt_new - dt_old)/2, and a
// position correction alone (eq. 13) cannot undo a velocity error that persists in all later steps;
// eq. 13 as printed is offered as Printed, and the single-particle test measures its error.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/eos.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// Eq. 12 for one particle, with the same viscous and force limits as the global step.
template <class Real>
struct ParticleDtLimits {
  Real h, courant, dt_max, viscous, force;
  EquationOfState<Real> eos;

  template <int Dim>
  CELLSPH_HD Real operator()(const ParticleView<Dim, Real>& pv, std::size_t i) const {
    const Real alpha = courant;
    const PhaseParams<Real>& ph = pv.phase_of(i);
    Real dt = std::min(dt_max, alpha * h / eos.sound_speed(ph.rest_density));
    if (ph.viscosity > 0) dt = std::min(dt, viscous * h * h * ph.rest_density / ph.viscosity);
    const Real v = norm(pv.v[i]);
    if (v > 0) dt = std::min(dt, alpha * h / v);
    const Real a = norm(pv.f[i]) / pv.m[i];
    if (a > 0) dt = std::min(dt, force * std::sqrt(h / a));
    return dt;
  }
};

// The smallest particle time of `set` (the global clock); INT64_MAX for an empty set.
template <int Dim, class Real>
std::int64_t earliest_tick(const ParticleView<Dim, Real>& pv, const IndexSet& set) {
  std::int64_t t = std::numeric_limits<std::int64_t>::max();
  for (const std::uint32_t i : set) t = std::min(t, pv.tick[i]);
  return t;
}

// Positions at the clock T: xs_i = x_i + (T - t_i) v_i for the particles not due (xs holds x before).
template <int Dim, class Real>
struct ExtrapolatePass {
  ParticleView<Dim, Real> pv;
  Vec<Dim, Real>* xs;
  std::int64_t T;
  Real unit;  // seconds per tick

  CELLSPH_HD void operator()(std::size_t i) const {
    if (pv.tick[i] != T) xs[i] += pv.v[i] * (static_cast<Real>(T - pv.tick[i]) * unit);
  }
};

// The forces of a due particle i read, for every fluid neighbour j within h_i, its density, pressure and
// volume (eq. 8a-c) and, with CSF, its normal, which reads the densities of j's own neighbours. Densities
// are therefore needed on due + N(due) (+ N(N(due)) with CSF), normals on due + N(due); anything more
// would be computed and never read. Marks only ever set bits, so the sets do not depend on the order in
// which threads mark them. `full`: every fluid particle in both sets. Host code (atomic marks).
template <int Dim, class Real>
void build_work_sets(const ParticleView<Dim, Real>& pv, const IndexSet& fluid, const IndexSet& due, bool csf,
                     bool full, std::vector<std::uint8_t>& mark, IndexSet& normal_set, IndexSet& rho_set) {
  // When every particle is due (often: a uniform limit such as alpha h / c binds them all), the sets are
  // the whole fluid and the marking pass would be pure overhead.
  if (full || due.size() == fluid.size()) {
    rho_set = fluid;
    normal_set = csf ? fluid : IndexSet{};
    return;
  }
  constexpr std::uint8_t kRho = 1, kNormal = 2;
  mark.assign(pv.n, 0);
  auto mark_around = [&](const IndexSet& from, std::uint8_t bits) {
    run_pass(from, [&](std::size_t i) {
      std::atomic_ref<std::uint8_t>(mark[i]).fetch_or(bits, std::memory_order_relaxed);
      const Vec<Dim, Real> xi = pv.x[i];
      const Real hi2 = pv.h[i] * pv.h[i];
      for (const auto* it = pv.candidates_begin(i); it != pv.candidates_end(i); ++it) {
        const std::uint32_t j = *it;
        if (!pv.is_fluid(j) || distance2(xi, pv.x[j]) > hi2) continue;  // the passes' own test
        std::atomic_ref<std::uint8_t>(mark[j]).fetch_or(bits, std::memory_order_relaxed);
      }
    });
  };
  auto collect = [&](IndexSet& out, std::uint8_t bit) {
    out.clear();
    for (const std::uint32_t i : fluid)
      if (mark[i] & bit) out.push_back(i);
  };
  if (csf) {
    mark_around(due, static_cast<std::uint8_t>(kRho | kNormal));
    collect(normal_set, kNormal);
    mark_around(normal_set, kRho);
  } else {
    mark_around(due, kRho);
    normal_set.clear();
  }
  collect(rho_set, kRho);
}

// A due particle's new level, its step-change correction and the leap-frog kick and drift (Algorithm 1).
template <int Dim, class Real>
struct PerParticleLevelPass {
  ParticleView<Dim, Real> pv;
  ParticleDtLimits<Real> limits;
  std::int64_t T;  // the clock [ticks]
  int L;           // max_level
  Real unit;       // seconds per tick
  Real dt_max;
  bool started;  // leap-frog started: v holds v(t - dt_old/2)
  StepChangeCorrection corr;

  CELLSPH_HD void operator()(std::size_t i) const {
    int level = 0;
    const Real want = limits(pv, i);
    while (level < L && dt_max / static_cast<Real>(std::int64_t{1} << level) > want) ++level;
    const int old = pv.level[i];
    // A coarser step must start on a multiple of itself, so that particles stay synchronised.
    while (level < old && T % (std::int64_t{1} << (L - level)) != 0) ++level;
    const Real dt_new = static_cast<Real>(std::int64_t{1} << (L - level)) * unit;
    const Real dt_old = static_cast<Real>(std::int64_t{1} << (L - old)) * unit;
    const Vec<Dim, Real> a = pv.f[i] / pv.m[i];
    if (!started) {
      pv.v[i] += a * (dt_new / 2);  // from v(t0) straight to v(t0 + dt/2) (eq. 11 initialisation)
    } else if (corr == StepChangeCorrection::Exact) {
      pv.v[i] += a * ((dt_old + dt_new) / 2);
    } else {
      if (level != old) pv.x[i] += a * ((dt_new * dt_new - dt_old * dt_old) / 8);
      pv.v[i] += a * dt_new;
    }
    pv.x[i] += pv.v[i] * dt_new;
    pv.level[i] = level;
    pv.tick[i] = T + (std::int64_t{1} << (L - level));
  }
};

// The due particles' levels, corrections, kicks and drifts at the clock T (ticks); `started`: the
// leap-frog has started (v holds v(t - dt_old/2)).
template <int Dim, class Real>
void per_particle_levels(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                         const IndexSet& due, std::int64_t T, bool started) {
  const int L = cfg.time.max_level;
  const Real unit = cfg.time.dt_max / static_cast<Real>(std::int64_t{1} << L);
  const ParticleDtLimits<Real> limits{cfg.support,      cfg.time.courant, cfg.time.dt_max,
                                      cfg.time.viscous, cfg.time.force,   cfg.eos};
  run_pass(due, PerParticleLevelPass<Dim, Real>{pv, limits, T, L, unit, cfg.time.dt_max, started,
                                                cfg.time.correction});
}

}  // namespace cellsph
