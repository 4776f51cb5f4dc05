#pragma once
// The fluid's density and pressure at the start of an explicit model's step: the summation density (eq. 7
// or the number density, models/summation_density.hpp) or, with density_evolution = continuity, the
// pressure of the density the continuity equation carries (models/continuity_density.hpp).
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/continuity_density.hpp"
#include "cellsph/solver/models/summation_density.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <int Dim, class Real, class Set>
void fluid_density_pressure(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv,
                            const Set& set) {
  if (cfg.density_evolution == DensityEvolution::Continuity)
    continuity_state(cfg, pv, set);
  else
    summation_density(cfg, pv, set);
}

}  // namespace cellsph
