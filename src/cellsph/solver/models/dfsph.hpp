#pragma once
// Divergence-free SPH (Bender & Koschier, SCA 2015 and TVCG 2017; Model::Dfsph): an incompressible model
// whose pressure is solved implicitly, so that the step is limited by the flow speed (CFL) rather than by
// an artificial speed of sound. One step, on the rows of the fluid particles (cut to h):
//  1. DfsphDensityFactorPass: summation density (fluid m_j W_ij plus Akinci 2012 walls psi_b W_ib) and
//     the factor alpha_i = 1 / (|sum_j m_j grad W_ij + sum_b psi_b grad W_ib|^2 + sum_j |m_j grad W_ij|^2);
//  2. the step: dt = min(dt_max, courant * d / max |v|, viscous * h^2 / nu) with d the particle
//     diameter (V^(1/Dim)), or time.dt when the stepping is fixed;
//  3. the divergence-free solve: Jacobi sweeps on k_i = p_i / rho_i^2 until the average of
//     max(D rho_i / Dt, 0) dt / rho0 is at most max_divergence_error (percent);
//  4. the non-pressure forces (gravity, the laminar viscosity of Morris et al. 1997,
//  physics/interactions.hpp) and v* = v + dt f/m;
//  5. the constant-density solve: Jacobi sweeps until the average of max(rho*_i - rho0, 0) / rho0, with
//     rho*_i = rho_i + dt D rho_i / Dt, is at most max_density_error (percent);
//  6. x += dt v, p_i = k_i rho_i^2 (the density solve's pressure, also its next warm start).
// A sweep sets k_i = max(source_i, 0) alpha_i / dt^2 (density; / dt for the divergence) and changes
// v_i by -dt sum_j m_j (k_i + k_j) grad W_ij - dt sum_b psi_b k_i grad W_ib (symmetric_pressure_force with
// the wall's k = 0: the gradient of i's density constraint, so alpha_i is exactly the Jacobi diagonal).
// Warm starts (2017 paper): each solve begins with half of the last step's k where the particle is
// compressed (the density solve: dfsph.warm_start_scale of it). The density solve may instead be the
// conjugate-gradient one of models/dfsph_cg.hpp (dfsph.density_solver = cg).
// The sweeps of the mass density (one phase) gather two arrays a pair, not three or four: with the step's
// G_i = sum_j w_ij grad W_ij (df_gsum, from the density pass), D rho_i / Dt = v_i . G_i - sum_j (w_j v_j) .
// grad W_ij and the kick -dt (k_i G_i + sum_j (m_j k_j) grad W_ij), with w_j v_j (df_mv) kept by every pass
// that changes v and m_j k_j (df_mk, 0 for a wall) by the source pass: the same sums regrouped (the pair
// force's k_i part summed once), so Newton's third law holds to rounding, no longer bit for bit. Every pass
// writes only its own particle's entries; the error averages are reduce_sum (pass_driver.hpp), whose result
// does not depend on the thread count.
//
// Several phases (density = number, Solenthaler & Pajarola 2008): rho_i = m_i delta_i with
// delta_i = sum_j W_ij + sum_b (V_b / V_i) W_ib, V_i = m_i / rho0_i, V_b = psi_b / rho0_b, i.e.
// rho_i = sum_j w_ij W_ij with the weight w_ij = m_i for a fluid neighbour and rho0_i V_b for a wall
// (dfsph_weight; a wall counts as V_b / V_i particles of i's phase, so a wall weighted for water holds oil
// at oil's rest density). The constraint is rho_i / rho0_i = 1 per particle (errors relative to rho0_i).
// With G_ij = grad_{x_j} rho_i (G_ii = sum_j w_ij grad W_ij, G_ij = -m_i grad W_ij for fluid j):
//  * D rho_i / Dt = sum_j w_ij v_ij . grad W_ij (= sum_l G_il . v_l);
//  * the sweep's force of i's constraint on particle l is -k_i m_i G_il (it sums to 0 over l); with j's
//    it gives the pair force f_ij = -(m_i^2 k_i + m_j^2 k_j) grad W_ij = -(p_i / delta_i^2 + p_j /
//    delta_j^2) grad W_ij (number_density_pressure_force, f_ji = -f_ij) and the wall term
//    -m_i k_i rho0_i V_b grad W_ib, with k = p / rho^2 as in the mass density;
//  * k_i alone changes D rho_i / Dt by -dt k_i sum_l m_i |G_il|^2 / m_l, so
//    alpha_i = 1 / (|G_ii|^2 + sum_j m_i^3 / m_j |grad W_ij|^2), the Jacobi diagonal again.
// For one phase (m_j = m_i, rho0 of the walls = rho0_i) every term is the mass density's; that path keeps
// its own expressions (number = false).
//
// The density uses the density kernel, and so do its gradient (the time derivative of that density) and
// the viscosity's gradient: pressure_kernel is not read by this model.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/hd.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/timestep/global_courant.hpp"

namespace cellsph {

// What the DFSPH solves did, for the progress line, tests and benchmarks.
struct DfsphStats {
  std::uint64_t steps = 0;
  std::uint64_t density_iterations = 0;     // sweeps of the constant-density solver, summed over steps
  std::uint64_t divergence_iterations = 0;  // sweeps of the divergence-free solver, summed over steps
  int last_density_iterations = 0;
  int last_divergence_iterations = 0;
  double last_density_error = 0;         // average density error reached in the last step [% of rho0]
  double last_divergence_error = 0;      // average divergence error reached in the last step [% per step]
  double max_density_error = 0;          // the largest of last_density_error over the steps
  std::uint64_t max_iteration_hits = 0;  // solves stopped by max_iterations above their error bound
  std::uint64_t last_hit_step = 0;       // the step (1-based) of the last such solve
  double last_hit_error = 0;             // and the error [%] it reached,
  double last_hit_bound = 0;             // its bound [%],
  int last_hit_iterations = 0;           // its sweeps (or iterations)
  const char* last_hit_solve = "";       // and which solve it was ("DFSPH constant-density"; a literal)
  const char* last_hit_unit = "sweeps";  // what its iterations are called ("sweeps", "iterations"; a literal)
  // Wall time of the step's stages [ms, summed]: ms_divergence includes the non-pressure forces (summed in
  // the divergence solve's last pass), ms_nonpressure is their kick.
  double ms_factor = 0, ms_divergence = 0, ms_nonpressure = 0, ms_density = 0, ms_drift = 0;
  double ms_walls = 0;  // volume-map walls: the step's look-up (boundary/bender2019.hpp)
};

// The step's kernel gradients of i's row, as the density pass stored them (df_grad, one per slot of the
// row, in its order; positions do not change during the solves, and x_ij * gradW_factor has gradW's
// bits). Stored as vectors, not as the scalar W'(r)/r: a sweep's pair then reads its gradient in order
// instead of gathering x_j. The loops walk this pointer beside the row's: one increment a pair, where
// indexing by the row slot cost the pair loop four more instructions.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real>* dfsph_row_grads(const ParticleView<Dim, Real>& pv, std::size_t i) {
  return pv.df_grad + (pv.row_begin(i) - pv.within);
}

// The weight a neighbour j carries in i's density rho_i = sum_j w_ij W_ij: m_j for the mass density; for the
// number density (Solenthaler & Pajarola 2008, rho_i = m_i sum_j W_ij) m_i for a fluid neighbour and
// rho0_i V_b = rho0_i psi_b / rho0_b for a wall particle (it counts as V_b / V_i particles of i's phase, as
// in models/summation_density.hpp). The same weight enters the gradient, the rate, alpha and the kick.
template <int Dim, class Real>
CELLSPH_HD inline Real dfsph_weight(const ParticleView<Dim, Real>& pv, bool number, std::size_t i,
                                    std::uint32_t j) {
  if (!number) return pv.m[j];
  return pv.is_fluid(j) ? pv.m[i] : pv.m[j] / pv.rho0[j] * pv.rho0[i];
}

// A per-pair callback that does nothing: the rates below walk the row alone.
struct DfsphNoPairWork {
  template <class V>
  CELLSPH_HD void operator()(std::uint32_t, const V&) const {}
};

// D rho_i / Dt = sum_j w_ij v_ij . grad W_ij (walls: their weight, their prescribed velocity), over i's
// rows, with the step's gradients (df_grad, written by the density pass). also(j, grad W_ij) is called for
// each pair on the way, in row order: another pass's sums ride along the same walk (DfsphSourceForcesPass).
template <int Dim, class Real, class Also = DfsphNoPairWork>
CELLSPH_HD inline Real dfsph_density_rate(const ParticleView<Dim, Real>& pv, std::size_t i, bool number,
                                          const Also& also = {}) {
  const Vec<Dim, Real> vi = pv.v[i];
  Real d = 0;
  const Vec<Dim, Real>* g = dfsph_row_grads(pv, i);
  for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it, ++g) {
    const std::uint32_t j = *it;
    d += continuity_term(*g, dfsph_weight(pv, number, i, j), vi - pv.v[j]);
    also(j, *g);
  }
  if (pv.vm_g) d += continuity_term(pv.vm_g[i], Real(1), vi);  // volume-map walls, at rest
  return d;
}

// The same rate regrouped for the mass density (the header): v_i . G_i - sum_j (w_j v_j) . grad W_ij.
template <int Dim, class Real, class Also = DfsphNoPairWork>
CELLSPH_HD inline Real dfsph_density_rate_factored(const ParticleView<Dim, Real>& pv, std::size_t i,
                                                   const Also& also = {}) {
  Real d = dot(pv.v[i], pv.df_gsum[i]);
  const Vec<Dim, Real>* g = dfsph_row_grads(pv, i);
  const std::uint32_t* row = pv.row_begin(i);
  const std::ptrdiff_t n = pv.row_end(i) - row;
  CELLSPH_SCALAR_LOOP
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    d -= dot(pv.df_mv[row[k]], g[k]);
    also(row[k], g[k]);
  }
  return d;
}

// Once a step, before the density pass, for every particle: w_j v_j and m_j k_j = 0 (the walls keep them
// through the step; the fluid's are rewritten by the passes that change v and k). The mass density's
// passes read them; the number density's do not, so its step skips this pass.
template <int Dim, class Real>
struct DfsphPairStatePass {
  ParticleView<Dim, Real> pv;
  CELLSPH_HD void operator()(std::size_t i) const {
    pv.df_mv[i] = pv.v[i] * pv.m[i];
    pv.df_mk[i] = Real(0);
  }
};

// The source of a sweep from i's rate D rho_i / Dt: writes k_i = source * alpha / dt^2 (density) or / dt
// (divergence) to df_kappa and returns i's error (relative to rho0; per step for the divergence). In warm
// mode instead: k_i = half the accumulated k where the source is positive (0 elsewhere), and the
// accumulator restarts at 0. DfsphSourcePass applies it; the density pass too, for the divergence solve's
// warm start.
template <class Real>
struct DfsphSourceRule {
  Real dt;
  bool density;                 // constant-density solve (else divergence-free)
  bool warm;                    // warm-start mode
  Real warm_scale;              // 0.5, or 0 without warm starts
  Real* acc;                    // the solve's accumulated k: pv.prho2 (density) or pv.df_kappa_v (divergence)
  std::uint32_t min_neighbors;  // divergence: fewer neighbours, no correction (splashes)

  template <int Dim>
  CELLSPH_HD Real apply(const ParticleView<Dim, Real>& pv, std::size_t i, Real rate) const {
    const Real rho0 = pv.rho0[i];
    Real source = 0;
    if (density) {
      source = std::max(pv.rho[i] + dt * rate - rho0, Real(0));
    } else if (pv.within_count[i] >= min_neighbors ||
               (pv.vm_count && Real(pv.within_count[i]) + pv.vm_count[i] >= Real(min_neighbors))) {
      source = std::max(rate, Real(0));
    }
    Real k;
    if (warm) {
      k = source > 0 ? warm_scale * acc[i] : Real(0);
      acc[i] = 0;
    } else {
      k = density ? source * pv.df_alpha[i] / (dt * dt) : source * pv.df_alpha[i] / dt;
    }
    pv.df_kappa[i] = k;
    pv.df_mk[i] = pv.m[i] * k;
    if (warm) return 0;
    return density ? source / rho0 : source * dt / rho0;
  }
};

// Step 1: density, volume, alpha, and the density solve's warm start k = p / rho^2 of the last step
// (read before rho is overwritten; p and rho are particle fields, so a checkpoint carries it). For the mass
// density (!number) it also takes the divergence solve's warm-start pass: that pass's rate is
// v_i . G_i - sum_j (w_j v_j) . grad W_ij with the velocities of the step's start, so its pair sum can ride
// along this loop (DfsphPairStatePass has written every w_j v_j before), one traversal of the rows less.
template <int Dim, class Real, class Kernel>
struct DfsphDensityFactorPass {
  ParticleView<Dim, Real> pv;
  Kernel w;
  Real denom_floor;  // below this the particle has too few neighbours for a pressure: alpha = 0
  bool number;       // number density (DensityFormulation::Number)
  bool mirror;       // walls' k mirrored from the fluid particle's (SolverConfig::Dfsph::mirror_walls())
  DfsphSourceRule<Real> warm_divergence;  // the divergence solve's warm start (mass density)

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const Real rho_old = pv.rho[i];
    const Real warm = rho_old > 0 ? pv.p[i] / (rho_old * rho_old) : Real(0);
    const V xi = pv.x[i];
    const Real mi = pv.m[i];
    Real rho = density_term(w, mi, Real(0));
    V grad{}, gwall{};
    Real sq = 0, mv_sum = 0;
    // Two loops over the row, the second reading back the first's gradients: one loop kept too many sums
    // live for the registers, and it carried them through memory (measured).
    V* gw = dfsph_row_grads(pv, i);  // the step's gradients, read by every sweep (positions fixed)
#if defined(__CUDA_ARCH__)
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it, ++gw) {
      const V xij = xi - pv.x[*it];
      const auto k = kernel_value_and_factor(w, xij, norm2(xij));
      rho += dfsph_weight(pv, number, i, *it) * k.value;  // density_term(w, w_ij, |x_ij|^2), bit for bit
      *gw = xij * k.factor;                               // = w.gradW(x_ij), bit for bit
    }
#else
    // On the host the row goes in blocks, its kernel evaluated in a loop of its own that the compiler
    // vectorizes: the square root and the division four pairs at a time, each lane with the scalar code's
    // bits (IEEE operations, no contraction); the sum stays in row order.
    constexpr int kBlock = 32;
    Real r2b[kBlock], valb[kBlock], facb[kBlock];
    for (const auto *it = pv.row_begin(i), *end = pv.row_end(i); it != end;) {
      const int n = static_cast<int>(end - it < kBlock ? end - it : kBlock);
      for (int t = 0; t < n; ++t) {
        gw[t] = xi - pv.x[it[t]];  // x_ij, times the factor below
        r2b[t] = norm2(gw[t]);
      }
      for (int t = 0; t < n; ++t) {
        const auto k = kernel_value_and_factor(w, gw[t], r2b[t]);
        valb[t] = k.value;
        facb[t] = k.factor;
      }
      for (int t = 0; t < n; ++t) {
        rho += dfsph_weight(pv, number, i, it[t]) * valb[t];  // density_term(w, w_ij, |x_ij|^2), bit for bit
        gw[t] = gw[t] * facb[t];                              // = w.gradW(x_ij), bit for bit
      }
      it += n;
      gw += n;
    }
#endif
    const V* gr = dfsph_row_grads(pv, i);
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it, ++gr) {
      const std::uint32_t j = *it;
      const Real wj = dfsph_weight(pv, number, i, j);
      const V g = *gr;
      const V mg = g * wj;
      grad += mg;
      if (!number) mv_sum += dot(pv.df_mv[j], g);
      // |grad_j rho_i|^2 m_i / m_j: m_i = m_j for the mass density of one phase (the 2015 paper's sum).
      // Without a branch on the kind: next to a wall it would be taken at random.
      const bool fluid = pv.is_fluid(j);
      const Real ratio = number ? mi / pv.m[j] : Real(1);
      sq += fluid ? norm2(mg) * ratio : Real(0);
      gwall += mg * (fluid ? Real(0) : Real(1));
    }
    if (pv.vm_g) {  // volume-map walls (boundary/bender2019.hpp): one wall neighbour more, at rest
      rho += pv.vm_rho[i];
      grad += pv.vm_g[i];
      gwall += pv.vm_g[i];
    }
    // k_i's own effect on D rho_i / Dt: its kick is -dt k_i (G_i + B_i) with the walls mirrored (B_i their
    // part of G_i), -dt k_i G_i without; so the diagonal is (G_i + B_i) . G_i + sq, or |G_i|^2 + sq. Next
    // to a wall G_i is small and (G_i + B_i) . G_i may be negative: then sq alone, a larger diagonal than
    // the true one (a shorter Jacobi step, never an overshoot).
    const Real denom = (mirror ? std::max(dot(grad + gwall, grad), Real(0)) : norm2(grad)) + sq;
    pv.rho[i] = rho;
    pv.vol[i] = pv.m[i] / rho;
    pv.df_alpha[i] = denom > denom_floor ? Real(1) / denom : Real(0);
    pv.df_gsum[i] = grad;
    pv.df_gwall[i] = gwall;
    pv.prho2[i] = warm;
    if (!number) warm_divergence.apply(pv, i, dot(pv.v[i], grad) - mv_sum);
  }
};

template <int Dim, class Real, class Kernel>
struct DfsphSourcePass {
  ParticleView<Dim, Real> pv;
  Kernel w;
  DfsphSourceRule<Real> rule;
  bool number;  // number density (DensityFormulation::Number)

  CELLSPH_HD Real operator()(std::size_t i) const {
    return rule.apply(pv, i, number ? dfsph_density_rate(pv, i, number) : dfsph_density_rate_factored(pv, i));
  }
};

// A sweep's velocity change from the k of the source pass; adds k_i to the accumulator. Inlined into the
// pass loop (GCC 12 otherwise calls it once a particle, reloading the pass's arrays): a sweep 2-4% faster.
template <int Dim, class Real, class Kernel>
struct DfsphPressureKickPass {
  ParticleView<Dim, Real> pv;
  Kernel w;
  Real dt;
  Real* acc;
  bool number;  // number density (DensityFormulation::Number)
  bool mirror;  // a wall's k is k_i (else 0)

  CELLSPH_HD CELLSPH_INLINE void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const Real mi = pv.m[i], ki = pv.df_kappa[i];
    if (acc) acc[i] += ki;  // null: a kick that is not part of the solve's sum (models/dfsph_cg.hpp)
    if (!number) {          // the regrouped sum (header): -m_i (k_i G_i + sum_j (m_j k_j) grad W_ij)
      V s = (mirror ? V(pv.df_gsum[i] + pv.df_gwall[i]) : pv.df_gsum[i]) * ki;
      const V* g = dfsph_row_grads(pv, i);
      const std::uint32_t* row = pv.row_begin(i);
      const std::ptrdiff_t n = pv.row_end(i) - row;
      CELLSPH_SCALAR_LOOP
      for (std::ptrdiff_t k = 0; k < n; ++k) s += g[k] * pv.df_mk[row[k]];
      pv.v[i] -= s * dt;
      pv.df_mv[i] = pv.v[i] * mi;
      return;
    }
    V f{};
    const V* g = dfsph_row_grads(pv, i);
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it, ++g) {
      const std::uint32_t j = *it;
      if (number && pv.is_fluid(j))
        f += number_density_pressure_force(*g, mi, pv.m[j], ki, pv.df_kappa[j]);
      else
        f += symmetric_pressure_force(*g, mi, dfsph_weight(pv, number, i, j), ki,
                                      pv.is_fluid(j) ? pv.df_kappa[j]
                                      : mirror       ? ki
                                                     : Real(0));
    }
    if (pv.vm_g) f += symmetric_pressure_force(pv.vm_g[i], mi, Real(1), ki, mirror ? ki : Real(0));
    pv.v[i] += f * (dt / mi);
    pv.df_mv[i] = pv.v[i] * mi;
  }
};

// Step 4: the non-pressure forces, as the WCSPH model's (models/wcsph.hpp) without pressure and tension.
// Its pair loop runs inside the divergence solve's last source pass (DfsphSourceForcesPass): the velocities
// it reads are the solve's final ones, and the row is walked once for both.
template <int Dim, class Real, class Kernel>
struct DfsphNonPressurePass {
  using V = Vec<Dim, Real>;
  ParticleView<Dim, Real> pv;
  Kernel w;
  V gravity;
  Real eta2;  // the laminar operator's regulariser 0.01 h_s^2 (h_s = support / 2), as in models/wcsph.hpp
  bool no_slip;
  bool
      number;  // number density: a wall's volume is its weight rho0_i V_b over rho_i, i.e. V_b rho0_i / rho_i
  bool hydrostatic;  // walls' pressure p_i + rho_i (g - a_b) . (x_b - x_i): that part here, once a step

  // Particle i's side of the sum, and the sum itself.
  struct Sum {
    V xi, vi, f;
    Real vol_i, mui, rhoi;
  };
  CELLSPH_HD Sum begin(std::size_t i) const {
    return {pv.x[i], pv.v[i], gravity * pv.m[i], pv.vol[i], pv.mu[i], pv.rho[i]};
  }
  CELLSPH_HD void pair(Sum& s, std::size_t i, std::uint32_t j, const V& g) const {
    const V xij = s.xi - pv.x[j];
    const Real r2 = norm2(xij);
    if (pv.is_fluid(j)) {
      s.f += morris_viscosity_force(V(s.vi - pv.v[j]), g, xij, r2, s.vol_i, pv.vol[j], s.mui, pv.mu[j], eta2);
      return;
    }
    const Real wb = dfsph_weight(pv, number, i, j);
    if (no_slip)
      s.f += morris_viscosity_force(V(s.vi - pv.v[j]), g, xij, r2, s.vol_i, wb / s.rhoi, s.mui, s.mui, eta2);
    // The pressure force's wall term -m_i w_b (p_b / rho_i^2) grad W_ib for the part of p_b beyond p_i
    // (the sweeps carry p_i's, mirrored): p_b - p_i = rho_i (g - a_b) . (x_b - x_i) = -rho_i (g - a_b) .
    // x_ib, with a_b a moving wall's acceleration (the wall's frame sees g - a_b, as Adami's walls do).
    if (hydrostatic) s.f += g * (pv.m[i] * wb * dot(pv.wall_gravity(gravity, j), xij) / s.rhoi);
  }
  CELLSPH_HD void finish(const Sum& s, std::size_t i) const {
    if (pv.vm_w == nullptr || !(pv.vm_w[i] > 0)) {
      pv.f[i] = s.f;
      return;
    }
    // Volume-map walls (boundary/bender2019.hpp): the same wall terms with the equivalent wall particle,
    // at rest (its weighted gradient w_b grad W_ib is vm_g).
    const Real wb = pv.vm_w[i];
    const V xib = pv.vm_x[i];
    V f = s.f;
    if (no_slip)
      f += morris_viscosity_force(s.vi, V(pv.vm_g[i] / wb), xib, norm2(xib), s.vol_i, wb / s.rhoi, s.mui,
                                  s.mui, eta2);
    if (hydrostatic)
      f += pv.vm_h[i] * (pv.m[i] / s.rhoi);  // rho0 T g: the walls' sum of w_b (g . x_ib) grad W_ib
    pv.f[i] = f;
  }

  CELLSPH_HD void operator()(std::size_t i) const {
    Sum s = begin(i);
    const V* gr = dfsph_row_grads(pv, i);
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it, ++gr) pair(s, i, *it, *gr);
    finish(s, i);
  }
};

// A source pass (DfsphSourcePass) that also sums the non-pressure forces, in the same walk over the rows:
// the divergence solve's passes that may be its last. Each sum is the one its own pass takes, in the same
// order, so the bits are those of the two passes run one after the other.
template <int Dim, class Real, class Kernel>
struct DfsphSourceForcesPass {
  using Forces = DfsphNonPressurePass<Dim, Real, Kernel>;
  DfsphSourcePass<Dim, Real, Kernel> source;
  Forces forces;

  // The forces' term of a pair, called by the rate's walk over the row.
  struct Along {
    const Forces& forces;
    typename Forces::Sum& sum;
    std::size_t i;
    CELLSPH_HD void operator()(std::uint32_t j, const Vec<Dim, Real>& g) const { forces.pair(sum, i, j, g); }
  };

  CELLSPH_HD Real operator()(std::size_t i) const {
    auto sum = forces.begin(i);
    const Along along{forces, sum, i};
    const Real rate = source.number ? dfsph_density_rate(source.pv, i, true, along)
                                    : dfsph_density_rate_factored(source.pv, i, along);
    forces.finish(sum, i);
    return source.rule.apply(source.pv, i, rate);
  }
};

template <int Dim, class Real>
struct DfsphKickPass {
  ParticleView<Dim, Real> pv;
  Real dt;
  CELLSPH_HD void operator()(std::size_t i) const {
    pv.v[i] += pv.f[i] * (dt / pv.m[i]);
    pv.df_mv[i] = pv.v[i] * pv.m[i];
  }
};

// Step 6.
template <int Dim, class Real>
struct DfsphDriftPass {
  ParticleView<Dim, Real> pv;
  Real dt;
  CELLSPH_HD void operator()(std::size_t i) const {
    pv.x[i] += pv.v[i] * dt;
    pv.p[i] = pv.prho2[i] * pv.rho[i] * pv.rho[i];
  }
};

struct DfsphSolveResult {
  int iterations = 0;
  double error = 0;  // relative (not percent)
};

// What every implicit solve's result is checked for (DFSPH's two, IISPH's one): an error that is not finite
// stops the run with a diagnosis naming the step, the solve (`what`, e.g. "DFSPH constant-density"), how many
// `unit`s ("sweeps", "iterations") it took and dt; one left above its bound `eta` by max_iterations is
// counted, and the last such solve kept (step, solve, sweeps, error and bound) for the run's warning lines
// and summary (app/cmd_run.cpp).
inline void implicit_check_solve(DfsphStats& st, const DfsphSolveResult& r, double eta, std::uint64_t step,
                                 double dt, const char* what, const char* unit) {
  if (!std::isfinite(r.error)) {
    std::ostringstream os;
    const std::string units(unit);  // "sweeps" -> "1 sweep"
    os << "simulation unstable at step " << step << ": the " << what << " solve diverged (average error not "
       << "finite after " << r.iterations << " "
       << (r.iterations == 1 ? units.substr(0, units.size() - 1) : units) << ", dt = " << dt << " s)";
    throw SimulationError(os.str());
  }
  if (r.error > eta) {
    ++st.max_iteration_hits;
    st.last_hit_step = step;
    st.last_hit_error = r.error * 100;
    st.last_hit_bound = eta * 100;
    st.last_hit_iterations = r.iterations;
    st.last_hit_solve = what;
    st.last_hit_unit = unit;
  }
}

// The divergence solve's warm start: half the last step's k, as SPlisHSPlasH (the full sum, measured, set
// the hydrostatic column and the dam break ringing). The density solve's is dfsph.warm_start_scale (0.5
// by default).
template <class Real>
inline constexpr Real kDfsphDivergenceWarmScale = Real(0.5);

// What a DFSPH step shares beyond its own particles: nothing in one process or on a device. A run across
// ranks (solver/simulation.cpp's RankExchange) refreshes the halo copies of what a pass wrote and a later
// pass reads of neighbours, and takes the errors' means and the step over every rank.
struct DfsphOneProcess {
  template <class Pv>
  void density(const Pv&) const {}  // after the density pass: rho, vol, the warm start's k and m k
  template <class Pv>
  void k(const Pv&) const {}  // after a source pass: k and m k
  template <class Pv>
  void v(const Pv&) const {}  // after a kick: v and m v
  template <class Real>
  Real min(Real dt) const {
    return dt;
  }
  // The mean of pass(i) over the set (a solve's error).
  template <class Set, class Pass>
  double mean(const Set& set, const Pass& pass) const {
    return reduce_sum(set, pass) / static_cast<double>(std::max<std::size_t>(set_size(set), 1));
  }
};

// The warm start's rule: warm_scale times the last step's k where the particle is compressed.
template <class Real>
DfsphSourceRule<Real> dfsph_warm_rule(Real dt, bool density, Real* acc, bool warm_start, Real warm_scale,
                                      std::uint32_t min_neighbors) {
  return {dt, density, true, warm_start ? warm_scale : Real(0), acc, min_neighbors};
}

// One solve (density or divergence): warm start, then sweeps until the average error is at most eta
// (relative) after at least min_it sweeps, or max_it sweeps were made. warm_k_set: the warm start's k are
// written already (the density pass writes the mass density's divergence warm start). forces: the
// non-pressure pass whose sums ride along every source pass that may be the solve's last (the velocities it
// reads are then the solve's final ones; a pass that turns out not to be the last only wrote f early).
template <int Dim, class Real, class Kernel, class Set, class Ex = DfsphOneProcess>
DfsphSolveResult dfsph_solve(const ParticleView<Dim, Real>& pv, const Set& set, const Kernel& w, Real dt,
                             bool density, Real* acc, double eta, int min_it, int max_it, bool warm_start,
                             Real warm_scale, std::uint32_t min_neighbors, bool number, bool mirror,
                             bool warm_k_set = false,
                             const DfsphNonPressurePass<Dim, Real, Kernel>* forces = nullptr,
                             const Ex& ex = Ex{}) {
  const DfsphPressureKickPass<Dim, Real, Kernel> kick{pv, w, dt, acc, number, mirror};
  if (!warm_k_set) {
    run_pass(set,
             DfsphSourcePass<Dim, Real, Kernel>{
                 pv, w, dfsph_warm_rule(dt, density, acc, warm_start, warm_scale, min_neighbors), number});
    ex.k(pv);
  }
  if (warm_start) {
    run_pass(set, kick);
    ex.v(pv);
  }
  const DfsphSourcePass<Dim, Real, Kernel> source{
      pv, w, DfsphSourceRule<Real>{dt, density, false, Real(0), acc, min_neighbors}, number};
  DfsphSolveResult r;
  for (;;) {
    const bool may_end = r.iterations >= min_it || r.iterations >= max_it;
    r.error = forces != nullptr && may_end
                  ? ex.mean(set, DfsphSourceForcesPass<Dim, Real, Kernel>{source, *forces})
                  : ex.mean(set, source);
    if (!std::isfinite(r.error)) return r;
    if ((r.iterations >= min_it && r.error <= eta) || r.iterations >= max_it) return r;
    ex.k(pv);
    run_pass(set, kick);
    ex.v(pv);
    ++r.iterations;
  }
}

// The particle diameter d = min over fluid particles of (m / rho0)^(1/Dim) (host arrays, once per run).
template <int Dim, class Real>
Real dfsph_particle_diameter(const Real* m, const Real* rho0, const IndexSet& fluid) {
  Real vmin = std::numeric_limits<Real>::max();
  for (const std::uint32_t i : fluid) vmin = std::min(vmin, m[i] / rho0[i]);
  return fluid.empty() ? Real(0) : static_cast<Real>(std::pow(double(vmin), 1.0 / Dim));
}
template <int Dim, class Real>
Real dfsph_particle_diameter(const ParticleView<Dim, Real>& pv, const IndexSet& fluid) {
  return dfsph_particle_diameter<Dim, Real>(pv.m, pv.rho0, fluid);
}

// Step 2 (DFSPH and IISPH): the step from the velocities at its start: time.dt when the stepping is fixed,
// else min(dt_max, dt_column, courant * d / max |v|, viscous * d^2 / max nu) (dt_column where set: the
// longest step a resting column of the scene's height holds, docs/physics.md "Model 3").
template <int Dim, class Real, class Set>
Real implicit_step_size(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                        const Set& fluid, Real diameter) {
  if (cfg.time.mode == TimeStepping::Fixed) return cfg.time.dt;
  Real nu_max = 0;
  for (const auto& ph : cfg.phases) nu_max = std::max(nu_max, ph.viscosity / ph.rest_density);
  Real dt = cfg.time.dt_max;
  if (cfg.time.dt_column > 0) dt = std::min(dt, cfg.time.dt_column);
  const auto mx = reduce_max(fluid, CourantMaxima<Real>{}, CourantLimitsPass<Dim, Real>{pv, false});
  if (mx.v2 > 0) dt = std::min(dt, cfg.time.courant * diameter / std::sqrt(mx.v2));
  // Explicit viscosity: the limit on the particle spacing, not the support (measured: on h = 2 d the
  // hydrostatic column at mu = 20 Pa s grew unstable at 0.4x the h-based limit).
  if (nu_max > 0) dt = std::min(dt, cfg.time.viscous * diameter * diameter / nu_max);
  return dt;
}

// Steps 1 and 2 (DFSPH and IISPH): w_j v_j and m_j k_j = 0 (mass density), the density pass with the
// divergence solve's warm start `warm_divergence`, then the step size.
template <int Dim, class Real, class Kernel, class Set, class All>
Real implicit_density_and_step(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                               const Set& fluid, const All& all, const Kernel& w, Real diameter,
                               const DfsphSourceRule<Real>& warm_divergence) {
  const Real h = cfg.support;
  Real rho0_min = std::numeric_limits<Real>::max();
  for (const auto& ph : cfg.phases) rho0_min = std::min(rho0_min, ph.rest_density);
  const Real denom_floor = Real(1e-9) * (rho0_min / h) * (rho0_min / h);
  const bool number = cfg.density == DensityFormulation::Number;
  // The mass density's divergence warm start rides along the density pass (its rule does not read dt).
  if (!number) run_pass(all, DfsphPairStatePass<Dim, Real>{pv});
  run_pass(fluid, DfsphDensityFactorPass<Dim, Real, Kernel>{pv, w, denom_floor, number,
                                                            cfg.dfsph.mirror_walls(), warm_divergence});
  return implicit_step_size(cfg, pv, fluid, diameter);
}

// Step 4's pass (DFSPH and IISPH): gravity, the laminar viscosity and the hydrostatic walls' rise.
template <int Dim, class Real, class Kernel>
DfsphNonPressurePass<Dim, Real, Kernel> implicit_forces_pass(const SolverConfig<Dim, Real>& cfg,
                                                             const ParticleView<Dim, Real>& pv,
                                                             const Kernel& w) {
  const Real h = cfg.support;
  return {pv,
          w,
          cfg.gravity,
          Real(0.01) * (h / 2) * (h / 2),
          cfg.no_slip,
          cfg.density == DensityFormulation::Number,
          cfg.dfsph.wall_pressure == DfsphWallPressure::Hydrostatic};
}

// One DFSPH step of the particles of `fluid` (rows filtered to h, pv's DFSPH arrays sized for every
// particle). `all` ranges over every particle, walls too (their df_mv and df_mk). Returns dt. Throws
// SimulationError when a solve's error is not finite. `step` is the number of the step being taken
// (1-based), for messages.
// `ex`: what the step shares beyond its particles (DfsphOneProcess; a run across ranks: RankExchange).
template <int Dim, class Real, class Set, class All, class Ex = DfsphOneProcess>
Real dfsph_step(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& fluid,
                const All& all, Real diameter, DfsphStats& st, std::uint64_t step, const Ex& ex = Ex{}) {
  const Real h = cfg.support;
  // A full neighbourhood holds about the support's volume over the particle volume; the divergence solve
  // leaves particles with fewer than 60% of that alone (SPlisHSPlasH's 20 of about 33 in 3D).
  const double ratio = double(h) / double(diameter);
  const double full = Dim == 3 ? 4.18879 * ratio * ratio * ratio : 3.14159 * ratio * ratio;
  const auto min_neighbors = static_cast<std::uint32_t>(0.6 * full);
  const double eta_density = double(cfg.dfsph.max_density_error) / 100;
  const double eta_divergence = double(cfg.dfsph.max_divergence_error) / 100;
  const bool number = cfg.density == DensityFormulation::Number;
  const bool mirror = cfg.dfsph.mirror_walls();

  Real dt = 0;
  with_kernel<Dim, Real>(cfg.density_kernel, h, [&](const auto w) {
    using K = std::remove_cvref_t<decltype(w)>;
    Stopwatch sw;
    dt = implicit_density_and_step(cfg, pv, fluid, all, w, diameter,
                                   dfsph_warm_rule(Real(0), false, pv.df_kappa_v, cfg.dfsph.warm_start,
                                                   kDfsphDivergenceWarmScale<Real>, min_neighbors));
    ex.density(pv);
    dt = ex.min(dt);
    st.ms_factor += sw.ms();
    sw.reset();

    // The divergence solve, which also sums the non-pressure forces (step 4) in its last source pass.
    const DfsphNonPressurePass<Dim, Real, K> forces = implicit_forces_pass(cfg, pv, w);
    const DfsphSolveResult div =
        dfsph_solve(pv, fluid, w, dt, false, pv.df_kappa_v, eta_divergence, 1, cfg.dfsph.max_iterations,
                    cfg.dfsph.warm_start, kDfsphDivergenceWarmScale<Real>, min_neighbors, number, mirror,
                    !number, &forces, ex);
    implicit_check_solve(st, div, eta_divergence, step, double(dt), "DFSPH divergence-free", "sweeps");
    st.ms_divergence += sw.ms();
    sw.reset();

    run_pass(fluid, DfsphKickPass<Dim, Real>{pv, dt});
    ex.v(pv);
    st.ms_nonpressure += sw.ms();
    sw.reset();

    const DfsphSolveResult den =
        cfg.dfsph.density_solver == DfsphDensitySolver::ConjugateGradient
            ? dfsph_solve_cg(pv, fluid, w, dt, pv.prho2, eta_density, cfg.dfsph.min_iterations,
                             cfg.dfsph.max_iterations,
                             cfg.dfsph.warm_start ? cfg.dfsph.warm_start_scale : Real(0), mirror)
            : dfsph_solve(pv, fluid, w, dt, true, pv.prho2, eta_density, cfg.dfsph.min_iterations,
                          cfg.dfsph.max_iterations, cfg.dfsph.warm_start, cfg.dfsph.warm_start_scale,
                          min_neighbors, number, mirror, false,
                          static_cast<const DfsphNonPressurePass<Dim, Real, K>*>(nullptr), ex);
    implicit_check_solve(st, den, eta_density, step, double(dt), "DFSPH constant-density", "sweeps");
    st.ms_density += sw.ms();
    sw.reset();

    run_pass(fluid, DfsphDriftPass<Dim, Real>{pv, dt});
    st.ms_drift += sw.ms();

    ++st.steps;
    st.divergence_iterations += static_cast<std::uint64_t>(div.iterations);
    st.density_iterations += static_cast<std::uint64_t>(den.iterations);
    st.last_divergence_iterations = div.iterations;
    st.last_density_iterations = den.iterations;
    st.last_divergence_error = div.error * 100;
    st.last_density_error = den.error * 100;
    st.max_density_error = std::max(st.max_density_error, st.last_density_error);
  });
  return dt;
}

}  // namespace cellsph

// The CG density solve that dfsph_step calls when dfsph.density_solver is "cg" (it builds on the passes
// above), and IISPH's step (Model::Iisph), which runs them too.
#include "cellsph/solver/models/dfsph_cg.hpp"  // IWYU pragma: export
#include "cellsph/solver/models/iisph.hpp"     // IWYU pragma: export
