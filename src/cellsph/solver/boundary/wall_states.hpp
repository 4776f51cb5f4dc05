#pragma once
// Walls that carry their own state (boundary.model adami or dynamic): each wall particle's pressure,
// density (and no-slip velocity) from its fluid neighbours, after the fluid's density pass
// (boundary/adami2012.hpp, boundary/dynamic_crespo2007.hpp). The wall rows (pv.wall_start, pv.wall_nbr)
// come from the backend: gathered from the fluid rows on the CPU, searched on a device.
#include "cellsph/solver/boundary/adami2012.hpp"
#include "cellsph/solver/boundary/dynamic_crespo2007.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <int Dim, class Real, class Set>
void wall_states(const SolverConfig<Dim, Real>& cfg, const ParticleView<Dim, Real>& pv, const Set& boundary) {
  if (cfg.wall_model == WallModel::Dynamic)
    dynamic_wall_states(cfg, pv, boundary);
  else
    adami2012_wall_states(cfg, pv, boundary);
}

}  // namespace cellsph
