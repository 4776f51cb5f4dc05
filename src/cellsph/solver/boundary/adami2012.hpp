#pragma once
// Boundary particles after Adami, Hu & Adams 2012 (WallModel::Adami): each step every wall particle w
// gets, from its fluid neighbours f (wall_neighbors.hpp),
//   p_w = (sum_f p_f W_wf + (g - a_w) . sum_f rho_f (x_w - x_f) W_wf) / sum_f W_wf (their eq. 27)
//   rho_w = the density at which the equation of state gives p_w                 (their eq. 28)
//   v~_w = 2 v_w - sum_f v_f W_wf / sum_f W_wf                                   (their eq. 22-23)
// with v_w and a_w the wall's prescribed velocity and acceleration (particles' v and wall_a; 0 for walls
// at rest, boundary/wall_motion.hpp)
// and the fluid-wall forces are then the fluid's own pair terms with these values (models/).
#include <cstddef>
#include <type_traits>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/eos.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// Run over the boundary particles after the density pass; writes p, rho, vol, prho2 and wall_v of b.
template <int Dim, class Real, class Kernel>
struct Adami2012WallStatePass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel
  EquationOfState<Real> eos;
  Vec<Dim, Real> gravity;

  CELLSPH_HD void operator()(std::size_t b) const {
    using V = Vec<Dim, Real>;
    const std::uint32_t* first = pv.wall_nbr + pv.wall_start[b];
    const std::uint32_t* last = pv.wall_nbr + pv.wall_start[b + 1];
    Real wsum = 0, psum = 0;
    V rsum{}, vsum{};
    for (const std::uint32_t* it = first; it != last; ++it) {
      const std::uint32_t f = *it;
      const V xwf = pv.x[b] - pv.x[f];
      const Real wwf = w.W2(norm2(xwf));
      wsum += wwf;
      psum += pv.p[f] * wwf;
      rsum += xwf * (pv.rho[f] * wwf);
      vsum += pv.v[f] * wwf;
    }
    // A wall particle no fluid particle reaches is read by no force; it keeps rest values.
    const V g = pv.wall_gravity(gravity, b);  // the wall's frame sees g - a_w
    Real pw = wsum > 0 ? (psum + dot(g, rsum)) / wsum : Real(0);
    if (eos.clamp_negative && pw < 0) pw = 0;
    const Real rhow = eos.density(pw, pv.rho0[b]);
    pv.p[b] = pw;
    pv.rho[b] = rhow;
    pv.vol[b] = pv.m[b] / rhow;
    pv.prho2[b] = pw / (rhow * rhow);
    pv.wall_v[b] = wsum > 0 ? pv.v[b] * Real(2) - vsum / wsum : V{};
  }
};

// The states of the wall particles of `boundary`, after the density pass and gather_wall_neighbors.
template <int Dim, class Real, class Set>
void adami2012_wall_states(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                           const Set& boundary) {
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    using K = std::remove_cvref_t<decltype(w)>;
    run_pass(boundary, Adami2012WallStatePass<Dim, Real, K>{pv, w, cfg.eos, cfg.gravity});
  });
}

}  // namespace cellsph
