#pragma once
// The CUDA write-up's weakly compressible SPH: density (summation, or the continuity equation's), wall
// states, the operator-split forces (Monaghan viscosity, gravity, tension; the symmetric pressure force
// apart), the floating bodies' loads, the step size, then symplectic Euler (models/wcsph.hpp); with the
// continuity density the kick, the density rate at the step's positions, the density update and the drift
// (models/continuity_density.hpp).
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/continuity_density.hpp"
#include "cellsph/solver/models/model_stepper.hpp"
#include "cellsph/solver/models/wcsph.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/timestep/global_courant.hpp"

namespace cellsph {

template <int Dim, class Real, class Ctx>
class WcsphStepper final : public ModelStepper<Dim, Real, Ctx> {
 public:
  Real advance(Ctx& c) override {
    const SolverConfig<Dim, Real>& cfg = c.cfg();
    const bool continuity = cfg.density_evolution == DensityEvolution::Continuity;
    f_pressure_.resize(c.size());
    if (continuity) drho_.resize(c.size());
    ParticleView<Dim, Real> pv = c.view();
    pv.f_pressure = f_pressure_.data();
    pv.drho = drho_.data();
    c.count_density(c.fluid_count());
    c.density(pv);
    c.wall_states(pv);
    c.count_forces(c.fluid_count());
    wcsph_forces(cfg, pv, c.fluid(), c.any_tension(), c.wall_states_on());
    c.body_loads(pv);
    c.forces_done();

    const Real dt = c.agree_dt(global_courant_dt(cfg, pv, c.fluid()));
    if (!continuity) {
      run_pass(c.fluid(), WcsphSymplecticEulerPass<Dim, Real>{pv, dt});
      return dt;
    }
    run_pass(c.fluid(), WcsphKickPass<Dim, Real>{pv, dt});
    c.share_velocity();  // the rate reads the neighbours' kicked velocities
    continuity_rate(cfg, pv, c.fluid());
    run_pass(c.fluid(), ContinuityIntegratePass<Dim, Real>{pv, dt});
    run_pass(c.fluid(), WcsphDriftPass<Dim, Real>{pv, dt});
    return dt;
  }

 private:
  // The step's pressure force (applied after the predicted velocity) and, with the continuity density,
  // d rho / dt.
  typename Ctx::template Array<Vec<Dim, Real>> f_pressure_;
  typename Ctx::template Array<Real> drho_;
};

}  // namespace cellsph
