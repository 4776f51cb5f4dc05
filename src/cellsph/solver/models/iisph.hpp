#pragma once
// Implicit incompressible SPH (Ihmsen, Cornelis, Solenthaler, Horvath & Teschner, IEEE TVCG 2014;
// Model::Iisph): the step's pressure from relaxed Jacobi iterations on the pressure Poisson equation, the
// second implicit solver beside DFSPH, run on DFSPH's passes (models/dfsph.hpp). One step:
//  1. DFSPH's density pass: rho_i, the row's kernel gradients, alpha_i;
//  2. the step (implicit_step_size: the CFL on the particle diameter, as DFSPH's);
//  3. the non-pressure forces (DfsphNonPressurePass) and v_adv = v + dt f / m;
//  4. the pressure solve on k_i = p_i / rho_i^2: k^0 = iisph.warm_start_scale times the last step's k
//     (every particle; 0 without warm starts), then iterations
//        k_i <- max(k_i + omega alpha_i (rho*_i - rho0_i) / dt^2, 0),  rho*_i = rho_i + dt D rho_i / Dt,
//     with D rho_i / Dt from the velocities kicked by the current k (DFSPH's kick: -dt sum_j m_j (k_i + k_j)
//     grad W_ij and the walls'), until the average error is at most iisph.max_density_error (percent);
//  5. x += dt v, p = k rho^2 (the next step's warm start).
// Why this is IISPH's iteration: with the pressure acceleration above, rho*_i is linear in the k, and the
// coefficient of k_i itself is -dt^2 (|sum_j m_j grad W_ij|^2 + sum_j m_i m_j |grad W_ij|^2) = -dt^2 /
// alpha_i (one phase; the walls in the first sum), IISPH's a_ii dt^2 for the unknown p_i / rho_i^2. Its
// relaxed Jacobi update p <- (1 - omega) p + omega (rho0 - rho_adv - sum_j (off-diagonal)) / a_ii is
// p <- p + omega (rho0 - rho*(p)) / a_ii, the line above. IISPH's two passes an iteration (d_ij p_j, then
// the update) are DFSPH's two (the kick, then the source). Where DFSPH's sweeps only add pressure (the
// compression max(rho* - rho0, 0) at omega = 1), IISPH takes it back where the fluid is expanded, keeping the
// total k >= 0 (its pressure clamp), relaxed by omega (0.5: Jacobi on this matrix overshoots at 1).
// The error is SPlisHSPlasH's for IISPH: the average over the fluid of (rho*_i - rho0_i) / rho0_i of the
// particles that hold pressure after the update (0 for the others), signed, of the iterate the update
// starts from.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/hd.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// The warm start: k_i = scale * the last step's k (acc, which restarts at 0; the kick that follows adds k
// back), for every particle of the set.
template <int Dim, class Real>
struct IisphWarmStartPass {
  ParticleView<Dim, Real> pv;
  Real scale;  // iisph.warm_start_scale, or 0 without warm starts
  Real* acc;   // the solve's accumulated k (pv.prho2)
  CELLSPH_HD void operator()(std::size_t i) const {
    const Real k = scale * acc[i];
    acc[i] = 0;
    pv.df_kappa[i] = k;
    pv.df_mk[i] = pv.m[i] * k;
  }
};

// An iteration's update (the header, step 4): from i's rate under the current k, the change of k_i
// (df_kappa, df_mk: the kick that follows applies it and adds it to acc), and i's error.
template <int Dim, class Real, class Kernel>
struct IisphUpdatePass {
  ParticleView<Dim, Real> pv;
  Kernel w;
  Real dt;
  Real omega;
  Real* acc;    // the accumulated k (pv.prho2)
  bool number;  // number density (DensityFormulation::Number)

  CELLSPH_HD Real operator()(std::size_t i) const {
    const Real rate = number ? dfsph_density_rate(pv, i, true) : dfsph_density_rate_factored(pv, i);
    const Real rho0 = pv.rho0[i];
    const Real residual = pv.rho[i] + dt * rate - rho0;  // rho*_i - rho0_i
    const Real total = std::max(acc[i] + omega * residual * pv.df_alpha[i] / (dt * dt), Real(0));
    const Real k = total - acc[i];
    pv.df_kappa[i] = k;
    pv.df_mk[i] = pv.m[i] * k;
    return total > 0 ? residual / rho0 : Real(0);
  }
};

// The pressure solve (step 4): the warm start and its kick, then iterations until the average error is at
// most eta (relative) after at least min_it of them, or max_it were made.
// `ex`: what the solve shares beyond its particles (models/dfsph.hpp, DfsphOneProcess).
template <int Dim, class Real, class Kernel, class Set, class Ex = DfsphOneProcess>
DfsphSolveResult iisph_solve(const ParticleView<Dim, Real>& pv, const Set& set, const Kernel& w, Real dt,
                             double eta, int min_it, int max_it, Real warm_scale, Real omega, bool number,
                             bool mirror, const Ex& ex = Ex{}) {
  Real* acc = pv.prho2;
  run_pass(set, IisphWarmStartPass<Dim, Real>{pv, warm_scale, acc});
  ex.k(pv);
  const DfsphPressureKickPass<Dim, Real, Kernel> kick{pv, w, dt, acc, number, mirror};
  run_pass(set, kick);
  ex.v(pv);
  const IisphUpdatePass<Dim, Real, Kernel> update{pv, w, dt, omega, acc, number};
  DfsphSolveResult r;
  for (;;) {
    r.error = ex.mean(set, update);
    if (!std::isfinite(r.error)) return r;
    if ((r.iterations >= min_it && r.error <= eta) || r.iterations >= max_it) return r;
    ex.k(pv);
    run_pass(set, kick);
    ex.v(pv);
    ++r.iterations;
  }
}

// One IISPH step of the particles of `fluid` (dfsph_step's contract: rows cut to h, the DFSPH arrays sized
// for every particle, `all` over every particle). Returns dt; throws SimulationError when the solve's error
// is not finite. Its statistics are DFSPH's (no divergence solve: those stay 0).
template <int Dim, class Real, class Set, class All, class Ex = DfsphOneProcess>
Real iisph_step(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& fluid,
                const All& all, Real diameter, DfsphStats& st, std::uint64_t step, const Ex& ex = Ex{}) {
  const bool number = cfg.density == DensityFormulation::Number;
  const bool mirror = cfg.dfsph.mirror_walls();
  Real dt = 0;
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    Stopwatch sw;
    // The density pass's divergence warm start has nothing to start here: its k are 0.
    dt = implicit_density_and_step(
        cfg, pv, fluid, all, w, diameter,
        dfsph_warm_rule(Real(0), false, pv.df_kappa_v, false, Real(0), std::uint32_t{0}));
    ex.density(pv);
    dt = ex.min(dt);
    st.ms_factor += sw.ms();
    sw.reset();

    run_pass(fluid, implicit_forces_pass(cfg, pv, w));
    run_pass(fluid, DfsphKickPass<Dim, Real>{pv, dt});
    ex.v(pv);
    st.ms_nonpressure += sw.ms();
    sw.reset();

    const double eta = double(cfg.dfsph.max_density_error) / 100;
    const DfsphSolveResult r =
        iisph_solve(pv, fluid, w, dt, eta, cfg.dfsph.min_iterations, cfg.dfsph.max_iterations,
                    cfg.dfsph.warm_start ? cfg.dfsph.warm_start_scale : Real(0), cfg.dfsph.relaxation, number,
                    mirror, ex);
    implicit_check_solve(st, r, eta, step, double(dt), "IISPH pressure", "iterations");
    st.ms_density += sw.ms();
    sw.reset();

    run_pass(fluid, DfsphDriftPass<Dim, Real>{pv, dt});
    st.ms_drift += sw.ms();

    ++st.steps;
    st.density_iterations += static_cast<std::uint64_t>(r.iterations);
    st.last_density_iterations = r.iterations;
    st.last_density_error = r.error * 100;
    st.max_density_error = std::max(st.max_density_error, st.last_density_error);
  });
  return dt;
}

}  // namespace cellsph
