#pragma once
// The density pass of both models: summation density (paper eq. 7, the write-up's mass density), or
// for the paper model the number density of Solenthaler & Pajarola 2008, then the equation of state.
// Writes rho, p and the per-particle quotients the pair passes read (V = m / rho, p / rho^2), so that
// pair loops divide once per particle, not per pair.
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

template <int Dim, class Real, class Kernel>
struct SummationDensityPass {
  ParticleView<Dim, Real> pv;
  Kernel w;  // the density kernel
  EquationOfState<Real> eos;
  bool number;  // number density (paper model, DensityFormulation::Number)

  CELLSPH_HD void operator()(std::size_t i) const {
    using V = Vec<Dim, Real>;
    const V xi = pv.x[i];
    Real rho = 0;
    if (number) {
      // Each neighbour counts by its volume, not its mass, so a light particle next to a heavy one
      // is not given the heavy one's density. A wall particle of volume V_b = psi_b / rho0_b counts as
      // V_b / V_i fluid particles (V_i = m_i / rho0_i), so that with one phase this is eq. 7 exactly.
      Real delta = w.W2(0);
      const Real inv_vol_i = pv.rho0[i] / pv.m[i];
      for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
        const std::uint32_t j = *it;
        const Real r2 = distance2(xi, pv.x[j]);
        const Real wij = w.W2(r2);
        delta += pv.is_fluid(j) ? wij : wij * (pv.m[j] / pv.rho0[j]) * inv_vol_i;
      }
      rho = pv.m[i] * delta;
    } else {
      rho = density_term(w, pv.m[i], Real(0));
      for (const auto* it = pv.row_begin(i); it != pv.row_end(i); ++it) {
        const Real r2 = distance2(xi, pv.x[*it]);
        rho += density_term(w, pv.m[*it], r2);
      }
    }
    pv.rho[i] = rho;
    const Real pres = eos.pressure(rho, pv.rho0[i]);
    pv.p[i] = pres;
    pv.vol[i] = pv.m[i] / rho;
    pv.prho2[i] = pres / (rho * rho);
  }
};

// Densities and pressures of `set` (pv.vol and pv.prho2 sized for every particle). Set: an IndexSet, or
// a device backend's index set (pass_driver.hpp).
template <int Dim, class Real, class Set>
void summation_density(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                       const Set& set) {
  const bool number = cfg.density == DensityFormulation::Number && cfg.model == Model::PaperMultiphase;
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    using K = std::remove_cvref_t<decltype(w)>;
    run_pass(set, SummationDensityPass<Dim, Real, K>{pv, w, cfg.eos, number});
  });
}

}  // namespace cellsph
