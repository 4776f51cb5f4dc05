#pragma once
// DFSPH's constant-density solve by preconditioned conjugate gradients (`dfsph.density_solver: "cg"`), in
// place of the Jacobi sweeps of models/dfsph.hpp. For the mass density of one phase the solve is linear
// in the pressures: with k_i = p_i / rho_i^2, a pressure change dk moves the velocities by the kick of
// DfsphPressureKickPass and so the predicted density errors s_i = rho_i + dt D rho_i / Dt - rho0 by
// -(A dk)_i, where A = dt^2 J J^T (J the Jacobian of the densities by the positions; walls at rest or
// mirrored add to the diagonal only) is symmetric and positive semi-definite. So:
//  * A p needs no matrix: kick the velocities with p (one traversal), take the errors again (one more)
//    and A p = s - s'; then v = v0 + a (v - v0) takes the step a along p. An iteration costs the two
//    traversals of a Jacobi sweep and a few passes over the particles;
//  * the preconditioner is the Jacobi sweep's own diagonal, alpha_i / dt^2;
//  * the pressure must stay >= 0 (no tension): the solve runs on an active set, the particles that are
//    compressed or hold pressure. When a step would make some k negative, or a particle outside the set
//    becomes compressed, the negative k are set to 0 (their velocity change undone by one more kick) and
//    CG restarts on the new set (an active-set method, as for contact problems).
// Because the solve can take pressure back, it may start from the whole of the last step's pressure
// (`warm_start_scale`), which the Jacobi sweeps, adding pressure only, cannot. It stops when the average
// of s_i over the particles that hold pressure, and of max(s_i, 0) over the others, is at most
// max_density_error: the Jacobi solve's measure, plus the expansion the pressure causes where the fluid is
// below rest density (so at least as strict).
// Every pass writes only its own particle's entries and the sums are reduce_sum, so the result does not
// depend on the thread count; the passes run on both backends (solver/pass_driver.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// The arrays of the solve (ParticleView::cg_*), and the step's constants.
template <int Dim, class Real>
struct DfsphCgState {
  ParticleView<Dim, Real> pv;
  Real dt;
  Real* acc;  // the accumulated k (pv.prho2)

  CELLSPH_HD Real error_of(std::size_t i) const {  // s_i, signed [kg/m^3]
    return pv.rho[i] + dt * dfsph_density_rate_factored(pv, i) - pv.rho0[i];
  }
  CELLSPH_HD Real preconditioned(std::size_t i, Real r) const { return r * pv.df_alpha[i] / (dt * dt); }
  // The residual of the active set: s_i where i is in it, else 0.
  CELLSPH_HD Real residual(std::size_t i) const { return pv.cg_active[i] ? pv.cg_s[i] : Real(0); }
};

// The warm start: k = scale times the last step's k, for every particle (the solve can take it back);
// the kick that applies it is DfsphPressureKickPass with the accumulator.
template <int Dim, class Real>
struct DfsphCgWarmPass {
  DfsphCgState<Dim, Real> c;
  Real scale;
  CELLSPH_HD void operator()(std::size_t i) const {
    const Real k = scale * c.acc[i];
    c.acc[i] = 0;
    c.pv.df_kappa[i] = k;
    c.pv.df_mk[i] = c.pv.m[i] * k;
  }
};

// (Re)start: the errors s, the active set, and the first direction p = M^-1 r. Returns r . M^-1 r.
template <int Dim, class Real>
struct DfsphCgStartPass {
  DfsphCgState<Dim, Real> c;
  CELLSPH_HD Real operator()(std::size_t i) const {
    const auto& pv = c.pv;
    const Real s = c.error_of(i);
    pv.cg_s[i] = s;
    pv.cg_active[i] = (s > 0 || c.acc[i] > 0) && pv.df_alpha[i] > 0 ? 1 : 0;
    const Real r = c.residual(i), z = c.preconditioned(i, r);
    pv.cg_p[i] = z;
    return r * z;
  }
};

// The stopping measure (relative to rho0): |s_i| where i holds pressure, max(s_i, 0) elsewhere.
template <int Dim, class Real>
struct DfsphCgErrorPass {
  DfsphCgState<Dim, Real> c;
  CELLSPH_HD Real operator()(std::size_t i) const {
    const Real s = c.pv.cg_s[i];
    return (c.acc[i] > 0 ? std::abs(s) : std::max(s, Real(0))) / c.pv.rho0[i];
  }
};

// Before A p: the direction p = M^-1 r + b p (b = 0 after a (re)start, where p = M^-1 r already), v kept,
// and the kick's k set to p (its increment; the accumulator is left alone).
template <int Dim, class Real>
struct DfsphCgDirectionPass {
  DfsphCgState<Dim, Real> c;
  Real b;
  CELLSPH_HD void operator()(std::size_t i) const {
    const auto& pv = c.pv;
    const Real p = b == 0 ? pv.cg_p[i] : c.preconditioned(i, c.residual(i)) + b * pv.cg_p[i];
    pv.cg_p[i] = p;
    pv.cg_v0[i] = pv.v[i];
    pv.df_kappa[i] = p;
    pv.df_mk[i] = pv.m[i] * p;
  }
};

// After the kick by p: A p = s - s' (s' the errors now); returns p . A p over the active set.
template <int Dim, class Real>
struct DfsphCgProductPass {
  DfsphCgState<Dim, Real> c;
  CELLSPH_HD Real operator()(std::size_t i) const {
    const auto& pv = c.pv;
    const Real ap = pv.cg_s[i] - c.error_of(i);
    pv.cg_ap[i] = ap;
    return pv.cg_active[i] ? pv.cg_p[i] * ap : Real(0);
  }
};

// The step a along p: v = v0 + a (v - v0), k += a p, s -= a A p. Returns the new r . M^-1 r.
template <int Dim, class Real>
struct DfsphCgUpdatePass {
  DfsphCgState<Dim, Real> c;
  Real a;
  CELLSPH_HD Real operator()(std::size_t i) const {
    const auto& pv = c.pv;
    pv.v[i] = pv.cg_v0[i] + (pv.v[i] - pv.cg_v0[i]) * a;
    pv.df_mv[i] = pv.v[i] * pv.m[i];
    c.acc[i] += a * pv.cg_p[i];
    pv.cg_s[i] -= a * pv.cg_ap[i];
    const Real r = c.residual(i);
    return r * c.preconditioned(i, r);
  }
};

// 1 where the active set must change: a negative k, or a compressed particle outside the set.
template <int Dim, class Real>
struct DfsphCgChangePass {
  DfsphCgState<Dim, Real> c;
  CELLSPH_HD Real operator()(std::size_t i) const {
    const auto& pv = c.pv;
    const bool joins = !pv.cg_active[i] && pv.cg_s[i] > 0 && pv.df_alpha[i] > 0;
    return c.acc[i] < 0 || joins ? Real(1) : Real(0);
  }
};

// A negative k back to 0: the kick's k is the difference (the kick, with the accumulator, applies it).
template <int Dim, class Real>
struct DfsphCgClampPass {
  DfsphCgState<Dim, Real> c;
  CELLSPH_HD void operator()(std::size_t i) const {
    const Real k = c.acc[i] < 0 ? -c.acc[i] : Real(0);
    c.pv.df_kappa[i] = k;
    c.pv.df_mk[i] = c.pv.m[i] * k;
  }
};

// The constant-density solve by CG on the active set (header): `kick` is the sweeps' pressure kick
// (DfsphPressureKickPass) with `acc` as its accumulator, `step_kick` the same without one (the kick by p).
template <int Dim, class Real, class Kernel, class Set>
DfsphSolveResult dfsph_solve_cg(const ParticleView<Dim, Real>& pv, const Set& set, const Kernel& w, Real dt,
                                Real* acc, double eta, int min_it, int max_it, Real warm_scale, bool mirror) {
  const DfsphCgState<Dim, Real> c{pv, dt, acc};
  const DfsphPressureKickPass<Dim, Real, Kernel> kick{pv, w, dt, acc, false, mirror};
  const DfsphPressureKickPass<Dim, Real, Kernel> step_kick{pv, w, dt, nullptr, false, mirror};
  if (warm_scale > 0) {
    run_pass(set, DfsphCgWarmPass<Dim, Real>{c, warm_scale});
    run_pass(set, kick);
  }
  const double n = static_cast<double>(std::max<std::size_t>(set_size(set), 1));
  double rz = reduce_sum(set, DfsphCgStartPass<Dim, Real>{c}), b = 0;
  DfsphSolveResult r;
  for (;;) {
    r.error = reduce_sum(set, DfsphCgErrorPass<Dim, Real>{c}) / n;
    if (!std::isfinite(r.error)) return r;
    if ((r.iterations >= min_it && r.error <= eta) || r.iterations >= max_it || !(rz > 0)) return r;
    run_pass(set, DfsphCgDirectionPass<Dim, Real>{c, static_cast<Real>(b)});
    run_pass(set, step_kick);
    const double pap = reduce_sum(set, DfsphCgProductPass<Dim, Real>{c});
    ++r.iterations;
    if (!(pap > 0)) {  // no descent along p (round-off once converged): undo the kick by p, stop
      run_pass(set, DfsphCgUpdatePass<Dim, Real>{c, Real(0)});
      return r;
    }
    const double rz_next = reduce_sum(set, DfsphCgUpdatePass<Dim, Real>{c, static_cast<Real>(rz / pap)});
    if (reduce_sum(set, DfsphCgChangePass<Dim, Real>{c}) > 0) {
      // The active set changes: negative k back to 0 (the accumulator's kick undoes their velocity change),
      // then CG starts again from the new errors.
      run_pass(set, DfsphCgClampPass<Dim, Real>{c});
      run_pass(set, kick);
      rz = reduce_sum(set, DfsphCgStartPass<Dim, Real>{c});
      b = 0;
      continue;
    }
    b = rz_next / rz;
    rz = rz_next;
  }
}

}  // namespace cellsph
