#pragma once
// Each SPH interaction written once, as a small inline CELLSPH_HD function, so that the solver's passes
// (solver/models, solver/boundary) on the CPU and a device kernel all call the same expression.
// Convention: x_ij = x_i - x_j, v_ij = v_i - v_j, and every function returns the contribution of
// neighbour j to particle i. The passes call the forms over per-particle quantities (volumes V = m / rho
// and p / rho^2 computed once per particle by the density pass, one kernel gradient per pair); the
// PairInput forms compute those from masses and densities and call them (same expressions).
#include <cmath>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/physics/eos.hpp"

namespace cellsph {

// What a pair interaction needs to know about i and j.
template <int Dim, class Real>
struct PairInput {
  Vec<Dim, Real> xij;  // x_i - x_j
  Vec<Dim, Real> vij;  // v_i - v_j
  Real r;              // |x_ij|
  Real mi, mj;         // masses
  Real rhoi, rhoj;     // densities
  Real pi, pj;         // pressures
  Real mui, muj;       // dynamic viscosities
};

// ---- Density -----------------------------------------------------------------------------------

// Paper eq. 7 / write-up mass density: rho_i = sum_j m_j W(r_ij) (the self term j = i included by the
// caller).
template <class Real, class Kernel>
CELLSPH_HD inline Real density_term(const Kernel& w, Real mj, Real r2) {
  return mj * w.W2(r2);
}

// The continuity equation: d rho_i / dt = sum_j m_j (v_i - v_j) . grad W_ij, the exact time derivative of the
// summation sum_j m_j W_ij over the same neighbours. WCSPH's continuity density (walls with their weights and
// velocities) and DFSPH's density prediction and divergence (a wall enters with psi_b and v_j = 0) call it.
template <int Dim, class Real>
CELLSPH_HD inline Real continuity_term(const Vec<Dim, Real>& grad_w, Real mj, const Vec<Dim, Real>& vij) {
  return mj * dot(vij, grad_w);
}

// The pair weight of the SPH Laplacian of Brookshaw (1985) and Morris et al. (1997):
//   lap A_i = sum_j (A_i - A_j) F_ij,   F_ij = 2 V_j (x_ij . grad W_ij) / (|x_ij|^2 + eta2),
// eta2 (0.01 h^2) keeping it finite as r -> 0. Exact for quadratic fields on a full lattice in the limit;
// x_ij . grad W_ij <= 0, so F_ij <= 0 and the operator diffuses. The density diffusion and the laminar
// viscosity below are both this Laplacian.
template <int Dim, class Real>
CELLSPH_HD inline Real brookshaw_weight(const Vec<Dim, Real>& grad_w, const Vec<Dim, Real>& xij, Real r,
                                        Real vol_j, Real eta2) {
  return Real(2) * vol_j * dot(xij, grad_w) / (r * r + eta2);
}

// Density diffusion (delta-SPH) of Molteni & Colagrossi 2009: d rho_i / dt += delta h c0 lap(rho)_i, the pair
// term delta h c0 (rho_i - rho_j - drho_h) F_ij with F_ij = brookshaw_weight(...). Molteni's drho_h = 0;
// Fourtakas et al. 2019 subtract the hydrostatic density difference (hydrostatic_density_difference), so that
// a fluid at rest under gravity, whose density increases with depth, is not diffused towards uniform
// density (the diffusion of the total density is what makes a still tank sink at walls and free surfaces).
// Symmetric F_ij V_i = F_ji V_j: sum_i V_i (this term) = 0, the volume-weighted density is conserved.
template <class Real>
CELLSPH_HD inline Real density_diffusion_term(Real delta_h_c0, Real rhoi, Real rhoj, Real drho_h, Real fij) {
  return delta_h_c0 * (rhoi - rhoj - drho_h) * fij;
}

// Fourtakas et al. 2019: rho^H_i - rho^H_j, the difference of the hydrostatic densities at x_i and x_j, from
// the hydrostatic pressure difference rho0 g . x_ij through the equation of state (for Tait this is their
// rho0 ((1 + rho0 g z_ij / C_B)^(1/gamma) - 1)).
template <int Dim, class Real>
CELLSPH_HD inline Real hydrostatic_density_difference(const EquationOfState<Real>& eos, Real rho0,
                                                      const Vec<Dim, Real>& g, const Vec<Dim, Real>& xij) {
  return eos.density(rho0 * dot(g, xij), rho0) - rho0;
}

// ---- The paper's averaged forces (eq. 8a, 8b) --------------------------------------------------

// eq. 8a: -V_i V_j (P_i + P_j)/2 grad W^press. Antisymmetric in i and j, so momentum is conserved.
// grad_w = grad W^press(x_ij).
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> averaged_pressure_force(const Vec<Dim, Real>& grad_w, Real vol_i, Real vol_j,
                                                         Real pi, Real pj) {
  return grad_w * (-vol_i * vol_j * (pi + pj) / 2);
}

// eq. 8b: V_i V_j (mu_i + mu_j)/2 (v_j - v_i) lap W^visco. Symmetric weight, antisymmetric velocity.
// lap_w = lap W^visco(r_ij). Against a wall with i's viscosity the caller passes mu_j = mu_i ((mu + mu)/2
// is mu exactly).
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> averaged_viscosity_force(const Vec<Dim, Real>& vij, Real vol_i, Real vol_j,
                                                          Real mui, Real muj, Real lap_w) {
  return vij * (-vol_i * vol_j * (mui + muj) / 2 * lap_w);
}

template <int Dim, class Real, class Kernel>
CELLSPH_HD inline Vec<Dim, Real> averaged_pressure_force(const PairInput<Dim, Real>& in, const Kernel& w) {
  return averaged_pressure_force(w.gradW(in.xij), in.mi / in.rhoi, in.mj / in.rhoj, in.pi, in.pj);
}

template <int Dim, class Real, class Kernel>
CELLSPH_HD inline Vec<Dim, Real> averaged_viscosity_force(const PairInput<Dim, Real>& in, const Kernel& w) {
  return averaged_viscosity_force(in.vij, in.mi / in.rhoi, in.mj / in.rhoj, in.mui, in.muj,
                                  w.laplacian(in.r));
}

// ---- Colour field and interface tension (eq. 8c, 9; Mueller 2003 surface tension) ----------------

template <int Dim, class Real>
struct ColorField {
  Vec<Dim, Real> grad{};  // grad C_i
  Real lap = 0;           // lap C_i
};

// Algorithm 1, lines 11-12: grad C_i += V_j c_j grad W^poly, lap C_i += V_j c_j lap W^poly.
template <int Dim, class Real, class Kernel>
CELLSPH_HD CELLSPH_INLINE void accumulate_color(ColorField<Dim, Real>& c, const Vec<Dim, Real>& xij, Real r,
                                                Real vj, Real cj, const Kernel& w) {
  c.grad += w.gradW(xij) * (vj * cj);
  c.lap += vj * cj * w.laplacian(r);
}

// eq. 9: f = -sigma lap C grad C / |grad C|, applied only where |grad C| exceeds the threshold: inside
// a phase grad C is numerical noise and its direction meaningless (Mueller 2003's threshold l).
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> interface_tension_force(const ColorField<Dim, Real>& c, Real sigma,
                                                         Real threshold) {
  const Real g2 = norm2(c.grad);
  if (g2 <= threshold * threshold || g2 <= Real(0)) return Vec<Dim, Real>{};
  return c.grad * (-sigma * c.lap / std::sqrt(g2));
}

// ---- The write-up's WCSPH forces ---------------------------------------------------------------

// Symmetric pressure force: -m_i m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W_ij (momentum conserving), from
// prho2 = p / rho^2 of each particle.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> symmetric_pressure_force(const Vec<Dim, Real>& grad_w, Real mi, Real mj,
                                                          Real prho2_i, Real prho2_j) {
  return grad_w * (-mi * mj * (prho2_i + prho2_j));
}

// The same force with the number density of Solenthaler & Pajarola 2008 (delta_i = rho_i / m_i, volume
// 1 / delta_i): f_ij = -(p_i / delta_i^2 + p_j / delta_j^2) grad W_ij = -(m_i^2 k_i + m_j^2 k_j) grad W_ij
// with k = p / rho^2; f_ji = -f_ij bit for bit (the sum commutes, grad W_ji = -grad W_ij). DFSPH's sweeps
// with several phases (models/dfsph.hpp); for m_i = m_j it is the force above.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> number_density_pressure_force(const Vec<Dim, Real>& grad_w, Real mi, Real mj,
                                                               Real prho2_i, Real prho2_j) {
  return grad_w * (-(mi * mi * prho2_i + mj * mj * prho2_j));
}

template <int Dim, class Real, class Kernel>
CELLSPH_HD inline Vec<Dim, Real> symmetric_pressure_force(const PairInput<Dim, Real>& in, const Kernel& w) {
  return symmetric_pressure_force(w.gradW(in.xij), in.mi, in.mj, in.pi / (in.rhoi * in.rhoi),
                                  in.pj / (in.rhoj * in.rhoj));
}

// Laminar viscosity of Morris, Fox & Zhu 1997 (WCSPH's physical viscosity, phases[].viscosity in Pa s):
//   f_i = sum_j m_i m_j (mu_i + mu_j) / (rho_i rho_j) (x_ij . grad W_ij) / (|x_ij|^2 + eta2) v_ij,
// i.e. m_i / rho_i div(mu grad v) with the Laplacian above (for equal mu, m_i mu / rho_i lap v). Written with
// V_i V_j and F_ij / (2 V_j): f_ij = -f_ji exactly (momentum); it acts along v_ij, not x_ij, so it does not
// conserve angular momentum exactly (Morris's operator). r2 = |x_ij|^2.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> morris_viscosity_force(const Vec<Dim, Real>& vij,
                                                        const Vec<Dim, Real>& grad_w,
                                                        const Vec<Dim, Real>& xij, Real r2, Real vol_i,
                                                        Real vol_j, Real mui, Real muj, Real eta2) {
  return vij * (vol_i * vol_j * (mui + muj) * dot(xij, grad_w) / (r2 + eta2));
}

// hs: the smoothing length (support / 2) of the 0.01 hs^2 regulariser.
template <int Dim, class Real, class Kernel>
CELLSPH_HD inline Vec<Dim, Real> morris_viscosity_force(const PairInput<Dim, Real>& in, const Kernel& w,
                                                        Real hs) {
  return morris_viscosity_force(in.vij, w.gradW(in.xij), in.xij, in.r * in.r, in.mi / in.rhoi,
                                in.mj / in.rhoj, in.mui, in.muj, Real(0.01) * hs * hs);
}

// Monaghan's (1992) artificial viscosity, for approaching pairs (v_ij . x_ij < 0) only:
//   Pi_ij = -alpha c0 mu_ij / rho_ij,   mu_ij = h (v_ij . x_ij) / (|x_ij|^2 + 0.01 h^2),  rho_ij = (rho_i +
//   rho_j)/2, f_i = -sum_j m_i m_j Pi_ij grad W_ij,
// with h the smoothing length (support / 2) and c0 the speed of sound at rest. Its shear viscosity is about
// nu = alpha h c0 / (2 (d + 2)) (Monaghan 2005): a numerical damping, not the fluid's viscosity.
// alpha_c0_h = alpha c0 h (one product per pass), eps2 = 0.01 h^2.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> artificial_viscosity_force(const Vec<Dim, Real>& vij,
                                                            const Vec<Dim, Real>& grad_w,
                                                            const Vec<Dim, Real>& xij, Real r, Real mi,
                                                            Real mj, Real rhoi, Real rhoj, Real alpha_c0_h,
                                                            Real eps2) {
  const Real vx = dot(vij, xij);
  if (!(vx < 0)) return Vec<Dim, Real>{};
  const Real pi_ij = -alpha_c0_h * vx / (r * r + eps2) / ((rhoi + rhoj) / 2);
  return grad_w * (-mi * mj * pi_ij);
}

// ---- Boundary particles (Akinci et al. 2012) ----------------------------------------------------

// A boundary particle b of "volume mass" psi_b = rho0 V_b (V_b = 1 / sum_k W_bk over boundary particles)
// adds psi_b W_ib to a fluid density, and pushes as a fluid particle would whose density mirrors the
// fluid particle's (rho_b = rho_i) and whose pressure is the fluid's extrapolated hydrostatically
// (Adami et al. 2012, for a wall at rest):
//   p_b = p_i + rho_i g . (x_b - x_i),   f_i = -m_i psi_b (p_i + p_b) / rho_i^2 grad W_ib.
// Akinci's printed form keeps only p_i / rho_i^2; with it, the hydrostatic test finds the wall carrying
// half the weight it should (bottom pressure twice rho g H); without the extrapolation, 5-8% too high.
template <int Dim, class Real>
CELLSPH_HD inline Real mirrored_boundary_pressure(Real pi, Real rhoi, const Vec<Dim, Real>& g,
                                                  const Vec<Dim, Real>& xib) {
  return pi - rhoi * dot(g, xib);  // x_b - x_i = -x_ib
}

// grad_w = grad W_ib, taken by the caller so that it can serve the wall's viscous term too.
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> boundary_pressure_force(const Vec<Dim, Real>& grad_w, Real mi, Real rhoi,
                                                         Real pi, Real pb, Real psib) {
  return grad_w * (-mi * psib * (pi + pb) / (rhoi * rhoi));
}

}  // namespace cellsph
