#pragma once
// The paper's model (Onderik & Durikovic 2007, Algorithm 1) with a global step (fixed or Courant): density
// (eq. 7 and the state equation), wall states, the colour normals when the tension model reads them, the
// forces (eq. 8a-b, eq. 9), the step size and the leap-frog (eq. 11). Per-particle steps
// (timestep/per_particle_levels.hpp) run the same normals and forces through paper_normals_and_forces.
#include <cstddef>

#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/model_stepper.hpp"
#include "cellsph/solver/models/paper_multiphase.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/timestep/global_courant.hpp"

namespace cellsph {

// The forces of `set`, after the colour normals of `normal_set` (the particles those forces read) when the
// tension model needs them: every particle's normal is cleared first, in `normals`.
// `shared(normals)` runs between the two (a run across ranks: the halo copies' normals from their owners).
template <int Dim, class Real, class Set, class NormalSet, class Normals, class Shared>
void paper_normals_and_forces(const SolverConfig<Dim, Real>& cfg, ParticleView<Dim, Real> pv, const Set& set,
                              const NormalSet& normal_set, Normals& normals, PaperTension tension,
                              bool wall_states, Shared&& shared) {
  if (tension.needs_normals()) {
    zero_array(normals, pv.n);
    pv.normal = normals.data();
    paper_normals(cfg, pv, normal_set);
    shared(normals);
  }
  paper_forces(cfg, pv, set, tension, wall_states);
}

template <int Dim, class Real, class Ctx>
class PaperStepper final : public ModelStepper<Dim, Real, Ctx> {
 public:
  Real advance(Ctx& c) override {
    const SolverConfig<Dim, Real>& cfg = c.cfg();
    const ParticleView<Dim, Real> pv = c.view();
    c.count_density(c.fluid_count());
    c.density(pv);
    c.wall_states(pv);
    const auto tension = PaperTension::of(cfg, c.any_tension());
    c.count_forces(c.fluid_count());
    if (tension.needs_normals()) c.count_normals(c.fluid_count());
    paper_normals_and_forces(cfg, pv, c.fluid(), c.fluid(), normal_, tension, c.wall_states_on(),
                             [&](auto& normals) { c.share(normals); });
    c.forces_done();

    const Real dt = c.agree_dt(global_courant_dt(cfg, pv, c.fluid()));
    // On the first step v(t0) becomes v(t0 + dt/2); with a changing step the kick is the mean of both.
    LeapFrogClock<Real>& clock = c.clock();
    const Real kick = clock.started ? (clock.last_dt + dt) / 2 : dt / 2;
    run_pass(c.fluid(), PaperLeapFrogPass<Dim, Real>{pv, kick, dt});
    clock.started = true;
    return dt;
  }

 private:
  typename Ctx::template Array<Vec<Dim, Real>> normal_;  // CSF / Akinci 2013 colour normals of the step
};

}  // namespace cellsph
