#pragma once
// A model's stepper: the passes of one global time step of one model (the paper's, WCSPH, DFSPH, IISPH),
// from the step's neighbour rows to the drifted particles, written once for every backend. The backend
// (Simulation on the CPU, DeviceStepper on a device) searches the neighbours before and applies what every
// model shares after (the emitters' buffer, box and planes, the stability check, moving walls, floating
// bodies' motion, the clock). A stepper owns the per-particle arrays only its model reads (allocated in the
// backend's memory) and its statistics; model_registry.hpp is the one place that knows every model.
//
// A step context `Ctx` is what a stepper sees of the backend running it (HostStepContext in
// simulation.cpp, DeviceStepContext in device/device_stepper.hpp):
//   Ctx::Array<T>                  an array of T in the backend's memory (std::vector, DeviceArray);
//                                  (zero_array below fills one with 0)
//   cfg()                          the SolverConfig
//   view()                         ParticleView of the particles, the step's rows and the arrays every model
//                                  shares (rest density, volumes, p / rho^2, colour normals, wall states)
//   fluid()                        the fluid's index set
//   fluid_by_pairs()               the same set split between the threads by row length (CPU), for the
//                                  implicit solvers' sweeps; the plain set on a device
//   all()                          every slot, as the drivers take it (a count or a device range)
//   size(), fluid_count()          particle slots; fluid particles
//   pair_slots()                   entries of the rows (the size of per-pair arrays)
//   density(pv)                    density and pressure of the fluid (summation or continuity)
//   wall_states(pv)                Adami or dynamic walls: every wall particle's state (else nothing)
//   body_loads(pv)                 floating bodies: their loads from the forces just computed
//   any_tension(), wall_states_on()
//   particle_diameter()            (m / rho0)^(1/Dim), the smallest over the fluid
//   step_number()                  the step being taken, 1-based (messages)
//   clock()                        LeapFrogClock: the last step and whether the leap-frog has started
//   forces_done()                  the end of the force phase (the timings' split)
//   agree_dt(dt)                   the step every rank takes (a run across ranks: the smallest of theirs)
//   share(array)                   the same for an array of the stepper's (one entry per particle)
//   implicit_exchange()            the implicit solvers' exchanges (models/dfsph.hpp, DfsphOneProcess)
//   share_velocity()               after a pass changed velocities that a later pass reads of neighbours
//                                  (a run across ranks: the halo copies refreshed; density() and
//                                  wall_states() share their own outputs)
//   count_density(n), count_forces(n), count_normals(n)  work done, in particles (StepTimings)
#include <cstddef>
#include <string>
#include <vector>

#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

struct DfsphStats;  // models/dfsph.hpp

// What the paper's leap-frog carries from one step to the next (part of the integrator state).
template <class Real>
struct LeapFrogClock {
  Real last_dt = 0;
  bool started = false;  // particles' v holds v(t - dt/2)
};

template <int Dim, class Real, class Ctx>
class ModelStepper {
 public:
  ModelStepper() = default;
  ModelStepper(const ModelStepper&) = delete;
  ModelStepper& operator=(const ModelStepper&) = delete;
  virtual ~ModelStepper() = default;
  // One global step from the rows of its start: density, wall states, forces, the step size and the
  // integration. Returns the step taken.
  virtual Real advance(Ctx& ctx) = 0;
  // The implicit solves' iterations and errors (DFSPH, IISPH); null for the explicit models.
  virtual DfsphStats* solver_stats() { return nullptr; }
  // What `cellsph run` shows of the model, from the run's solver statistics `st` (this stepper's or, with a
  // device backend, the device's): its part of the progress line ("" for none) and its summary lines.
  [[nodiscard]] virtual std::string progress(const DfsphStats& /*st*/, Real /*last_dt*/) const { return {}; }
  [[nodiscard]] virtual std::vector<std::string> summary(const DfsphStats& /*st*/,
                                                         double /*search_ms*/) const {
    return {};
  }
};

// n entries of 0 in an array of either backend (std::vector, DeviceArray). Arrays every entry of which a
// pass writes before any is read are only resized.
template <class T>
void zero_array(std::vector<T>& a, std::size_t n) {
  a.assign(n, T{});
}
template <class A>
void zero_array(A& a, std::size_t n) {
  a.resize(n);
  a.zero();
}

}  // namespace cellsph
