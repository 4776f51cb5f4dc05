#pragma once
// The paper's multiphase model (Onderik & Durikovic 2007, Algorithm 1; Model::PaperMultiphase):
//  * density (eq. 7, or the number density): summation_density.hpp;
//  * colour normals for CSF (Brackbill 1992 / Morris 2000) or Akinci 2013 tension: PaperNormalsPass;
//  * forces f_i = m_i g + eq. 8a + eq. 8b + eq. 9 (or CSF, or Akinci 2013): PaperForcesPass;
//  * leap-frog integration (eq. 11): PaperLeapFrogPass.
// The pair formulas (eq. 8a-c, 9) are in physics/interactions.hpp; wall particles enter as the boundary
// model says (boundary/).
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/boundary/akinci2012.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// CSF normals n_i = sum_j V_j (c_j - c_i) grad W_ij: the difference form vanishes exactly inside a phase.
// Walls take the colour of the fluid particle, so they contribute nothing. Akinci 2013 (full): the
// full colour gradient h sum_j V_j grad W_ij (non-zero at a free surface).
template <int Dim, class Real>
struct PaperNormalsPass {
  ParticleView<Dim, Real> pv;
  Poly6Kernel<Dim, Real> wc;
  bool full;

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    V n{};
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
      const std::uint32_t j = *it;
      if (!pv.is_fluid(j)) continue;
      n += wc.gradW(pv.x[i] - pv.x[j]) *
           (full ? pv.m[j] / pv.rho[j] : pv.m[j] / pv.rho[j] * (pv.color[j] - pv.color[i]));
    }
    pv.normal[i] = full ? n * pv.h[i] : n;
  }
};

// Algorithm 1, lines 2-15: f_i = m_i g + eq. 8a + eq. 8b + eq. 9 (or CSF, or Akinci 2013).
template <int Dim, class Real, class PressureKernel>
struct PaperForcesPass {
  ParticleView<Dim, Real> pv;
  PressureKernel wp;  // eq. 8a's gradient (the paper: spiky)
  Poly6Kernel<Dim, Real> wc;
  ViscosityKernel<Dim, Real> wv;
  CohesionKernel<Dim, Real> coh;
  Vec<Dim, Real> gravity;
  Real lap_self;  // wc.laplacian(0)
  Real thr2;      // tension threshold squared
  Real tension_threshold;
  bool csf, akinci, eq9;  // the tension model, when any phase has sigma > 0
  bool wall_states;       // Adami or dynamic walls: wall particles carry p, rho, vol and wall_v
  bool no_slip;
  bool clamp_negative;  // the EOS's, for Akinci walls' mirrored pressure

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const Real vol_i = pv.m[i] / pv.rho[i];
    V f = gravity * pv.m[i];
    // The colour field includes particle i itself (its Laplacian does not vanish at r = 0), so that it
    // is ~0 inside a uniform phase.
    ColorField<Dim, Real> cf;
    cf.lap = vol_i * pv.color[i] * lap_self;
    const Real mi = pv.m[i], rhoi = pv.rho[i], pi = pv.p[i], mui = pv.mu[i];
    const bool csf_i = csf && norm2(pv.normal[i]) > thr2 && norm2(pv.normal[i]) > 0;
    const V nhat_i = csf_i ? pv.normal[i] / norm(pv.normal[i]) : V{};
    // CSF: kappa = -div(n / |n|) over neighbours with a defined normal, divided by their kernel sum
    // (Morris 2000): the sum alone takes n_j = n_i for the others (more than one support from the
    // interface) and underestimated the curvature by 17% (Laplace jump) whatever the resolution.
    Real kappa = 0, wsum = vol_i * wc.W2(0);
    const V vel_i = pv.v[i];
    for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
      const std::uint32_t j = *it;
      const V xij = pv.x[i] - pv.x[j];
      const Real r = norm(xij);
      if (pv.is_fluid(j)) {
        // eq. 8a, 8b with the per-particle volumes of the density pass.
        const Real vol_j = pv.vol[j];
        f += averaged_pressure_force(wp.gradW(xij), vol_i, vol_j, pi, pv.p[j]);
        f += averaged_viscosity_force(vel_i - pv.v[j], vol_i, vol_j, mui, pv.mu[j], wv.laplacian(r));
        if (csf_i && norm2(pv.normal[j]) > thr2 && norm2(pv.normal[j]) > 0) {
          const V nhat_j = pv.normal[j] / norm(pv.normal[j]);
          kappa -= vol_j * dot(nhat_j - nhat_i, wc.gradW(xij));
          wsum += vol_j * wc.W2(r * r);
        } else if (eq9) {
          accumulate_color(cf, xij, r, vol_j, pv.color[j], wc);
        } else if (akinci && pv.phase[j] == pv.phase[i] && r > 0) {
          // Akinci 2013: each factor is symmetric in (i, j) and x_ij, n_i - n_j antisymmetric: the
          // pair's forces on i and j are exact opposites.
          const Real sigma = pv.phase_of(i).sigma;
          const Real k = (pv.rho0[i] + pv.rho0[j]) / (rhoi + pv.rho[j]);
          f += (xij * (-sigma * mi * pv.m[j] * coh.C(r) / r) +
                (pv.normal[i] - pv.normal[j]) * (-sigma * (mi + pv.m[j]) / 2)) *
               k;
        }
      } else {
        // A boundary particle acts as fluid. Adami / dynamic walls (boundary/adami2012.hpp,
        // boundary/dynamic_crespo2007.hpp): eq. 8a and 8b as between two fluid particles, with the
        // wall's own pressure and volume psi_b / rho_w and its velocity; i's mu. Akinci walls
        // (boundary/akinci2012.hpp): i's density (mirrored, so that its volume psi_b / rho_i matches how
        // i sees fluid neighbours; with rho0 instead a resting fluid is pushed off the walls), i's
        // pressure extrapolated to it, and i's colour (walls are neutral to interface tension); no slip:
        // eq. 8b against the wall particle's velocity (0 at rest) with i's mu.
        const Real mj = pv.m[j];
        if (wall_states) {
          const Real vol_j = pv.vol[j];
          f += averaged_pressure_force(wp.gradW(xij), vol_i, vol_j, pi, pv.p[j]);
          if (no_slip)
            f += averaged_viscosity_force(vel_i - pv.wall_v[j], vol_i, vol_j, mui, mui, wv.laplacian(r));
        } else {
          const Real pj = akinci2012_wall_pressure(pi, rhoi, gravity, xij, clamp_negative);
          f += averaged_pressure_force(wp.gradW(xij), mi / rhoi, mj / rhoi, pi, pj);
          if (no_slip)
            f += averaged_viscosity_force(vel_i - pv.v[j], vol_i, mj / rhoi, mui, mui, wv.laplacian(r));
        }
        if (eq9) accumulate_color(cf, xij, r, mj / rhoi, pv.color[i], wc);
      }
    }
    if (csf_i) {
      f += pv.normal[i] * (pv.phase_of(i).sigma * kappa / wsum * vol_i);
    } else if (eq9) {
      // Eq. 9 has the units of a force density (sigma [N/m] times a curvature of C [1/m^2]); by the
      // paper's own eq. 6 the particle's force is V_i times it. Taken literally as a force it gives
      // accelerations ~1e5 m/s^2 for the paper's sigma, m and h.
      f += interface_tension_force(cf, pv.phase_of(i).sigma, tension_threshold) * vol_i;
    }
    pv.f[i] = f;
  }
};

// Leap-frog (eq. 11): v += f (kick / m), x += v dt. On the first step kick = dt/2, so that v(t0) lands on
// v(t0 + dt/2); after that kick = (dt_old + dt_new)/2, which keeps the velocity at the midpoints of the
// position steps when the step changes.
template <int Dim, class Real>
struct PaperLeapFrogPass {
  ParticleView<Dim, Real> pv;
  Real kick, dt;

  CELLSPH_HD void operator()(std::size_t i) const {
    pv.v[i] += pv.f[i] * (kick / pv.m[i]);
    pv.x[i] += pv.v[i] * dt;
  }
};

// ---- Launchers: the passes above with their parameters from the configuration --------------------

// Which tension the forces apply (none when no phase has sigma > 0).
struct PaperTension {
  bool csf = false, akinci = false, eq9 = false;
  template <int Dim, class Real>
  static PaperTension of(const SolverConfig<Dim, Real>& cfg, bool any_tension) {
    return {any_tension && cfg.tension == TensionModel::Csf,
            any_tension && cfg.tension == TensionModel::Akinci,
            any_tension && cfg.tension == TensionModel::Paper};
  }
  [[nodiscard]] bool needs_normals() const { return csf || akinci; }
};

// Normals of `set` (pv.normal sized for every particle).
template <int Dim, class Real, class Set>
void paper_normals(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& set) {
  run_pass(set, PaperNormalsPass<Dim, Real>{pv, Poly6Kernel<Dim, Real>(cfg.support),
                                            cfg.tension == TensionModel::Akinci});
}

// Forces of `set`, after the densities (and the normals, if tension.needs_normals()) they read.
template <int Dim, class Real, class Set>
void paper_forces(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& set,
                  PaperTension tension, bool wall_states) {
  const Poly6Kernel<Dim, Real> wc(cfg.support);
  with_kernel<Dim, Real>(cfg.pressure_kernel, cfg.support, [&](const auto wp) {
    using K = std::remove_cvref_t<decltype(wp)>;
    run_pass(set, PaperForcesPass<Dim, Real, K>{
                      pv, wp, wc, ViscosityKernel<Dim, Real>(cfg.support),
                      CohesionKernel<Dim, Real>(cfg.support), cfg.gravity, wc.laplacian(0),
                      cfg.tension_threshold * cfg.tension_threshold, cfg.tension_threshold, tension.csf,
                      tension.akinci, tension.eq9, wall_states, cfg.no_slip, cfg.eos.clamp_negative});
  });
}

}  // namespace cellsph
