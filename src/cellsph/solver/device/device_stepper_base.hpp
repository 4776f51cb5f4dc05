#pragma once
// What Simulation (simulation.hpp) sees of a device backend: the particles copied to the device once,
// steps run there (the state stays on the device between steps), and copies back only when asked (at
// output and checkpoint times). No CUDA type appears here: the CUDA implementation is in cuda/*.cu, the
// host-emulated one ("host device", for tests without a GPU) in host_device_stepper.cpp; both are the
// one template DeviceStepper (device_stepper.hpp) over a memory space.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cellsph/solver/boundary/rigid_bodies.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/models/model_stepper.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

template <class Real>
struct DeviceStepResult {
  Real dt = 0;                      // the step taken
  std::int64_t first_bad = -1;      // the lowest fluid index failing the stability check, or -1
  std::int64_t first_in_sink = -1;  // sinks: the lowest fluid index inside one at the step's end, or -1
  double neighbors_ms = 0;          // wall time of the phases (the device synchronised between them)
  double forces_ms = 0;
  double integration_ms = 0;
  bool leapfrog_started = false;  // the paper's leap-frog after the step (LeapFrogClock::started)
  double guard_corrections = 0;   // fluid particles put back out of solids (boundary/solid_guard.hpp)
};

// What a step needs of the Simulation's state: the clock (moving walls), the paper's leap-frog clock, and
// the number of the step being taken (1-based, for messages).
template <class Real>
struct DeviceStepInput {
  Real time = 0;
  LeapFrogClock<Real> clock{};
  std::uint64_t step = 0;
  // Emitters (emitters.hpp): per emitter 1 when it is active at the step's start (host memory, the
  // Simulation's); null when none is (no buffer is held).
  const std::uint8_t* emitters_active = nullptr;
  // The floating bodies' states at the step's start (the solid guard's frames); null without bodies.
  const std::vector<RigidBodyState>* bodies = nullptr;
};

// The device's neighbour rows copied to the host (tests, scripts/gpu_check.sh). Row i of a fluid particle
// is rows[offsets[i] .. offsets[i] + count[i]); wall row b is wall_rows[wall_start[b] .. wall_start[b + 1])
// (empty without wall states).
struct DeviceRows {
  std::vector<std::uint64_t> offsets;
  std::vector<std::uint32_t> count, rows, wall_start, wall_rows;
};

template <int Dim, class Real>
class DeviceStepperBase {
 public:
  DeviceStepperBase() = default;
  DeviceStepperBase(const DeviceStepperBase&) = delete;
  DeviceStepperBase& operator=(const DeviceStepperBase&) = delete;
  virtual ~DeviceStepperBase() = default;
  // Every field of the field list (particles.hpp) to the device (the index sets and rest densities are
  // derived from them there).
  virtual void upload(const Particles<Dim, Real>& p) = 0;
  // Dynamic walls: each wall particle's fixed wall-wall density (boundary/dynamic_crespo2007.hpp), which the
  // Simulation computes once from rows the device does not build; after upload(), indexed like its particles.
  virtual void upload_wall_self_density(const std::vector<Real>& rho) = 0;
  // Every field back into p (resized).
  virtual void download(Particles<Dim, Real>& p) = 0;
  // The solver state carried between steps (SolverState, particles.hpp: DFSPH's divergence warm start), to
  // the device after upload() and back (for checkpoints) with download_solver_state().
  virtual void upload_solver_state(const SolverState<Dim, Real>& s) = 0;
  virtual void download_solver_state(SolverState<Dim, Real>& s) = 0;
  // Moving walls (boundary/wall_motion.hpp): per moving wall k its slot, initial position and motion, and
  // every particle's wall acceleration at the current time (the Simulation's, after upload()); the motions
  // themselves come with the config.
  virtual void upload_wall_motion(const std::vector<std::uint32_t>& slot,
                                  const std::vector<Vec<Dim, Real>>& x0,
                                  const std::vector<std::int32_t>& motion,
                                  const std::vector<Vec<Dim, Real>>& wall_a) = 0;
  // Floating bodies (boundary/rigid_bodies.hpp), after upload(): their particles' slots, bodies and
  // offsets, per particle its body, per body its mass per particle, the contact constants. Their particles
  // get rows like the fluid's (within h: the fluid the reaction reads and the walls a contact reads).
  virtual void upload_bodies(const RigidBodySystem<Dim, Real>& bodies) = 0;
  // After step(): per body particle its force of the step (BodyReactionPass after the fluid's forces, plus
  // BodyContactPass) and its position (the step's start: body particles move only in place_bodies).
  virtual void download_body_forces(std::vector<Vec<Dim, double>>& f, std::vector<Vec<Dim, Real>>& x) = 0;
  // The body particles where `states` put them (BodyPlacePass: position, velocity, wall acceleration).
  virtual void place_bodies(const std::vector<RigidBodyState>& states) = 0;
  // One step of Simulation::step() with a global step: the emitters' buffer marked, neighbour rows, the
  // model's stepper (models/model_stepper.hpp: density to the drift), the buffer held, box and planes, the
  // stability check, the moving walls at the new time, then the sink test. Positions are left as computed
  // even when the check fails (as on the CPU). Emitting and removing particles is the Simulation's (on the
  // host, then upload() again).
  virtual DeviceStepResult<Real> step(const DeviceStepInput<Real>& in) = 0;
  // The rows of the current positions (built afresh), copied to the host.
  virtual DeviceRows neighbor_rows() = 0;
  // The model's implicit solves' statistics (models/model_stepper.hpp), in host memory; null for the
  // explicit models.
  virtual DfsphStats* solver_stats() = 0;
};

// Empty when the device step runs this config; otherwise what it lacks, in one phrase.
template <int Dim, class Real>
std::string device_step_unsupported(const SolverConfig<Dim, Real>& cfg) {
  if (cfg.time.mode == TimeStepping::PerParticle)
    return "per-particle time steps do not run on a device (time.stepping = fixed or courant)";
  if (cfg.wall_model == WallModel::VolumeMap)
    return "volume-map walls (boundary.model = volume-map) run on the CPU only for now";
  if (cfg.rigid_bodies.any() && !(cfg.rigid_bodies.contact_distance < double(cfg.support)))
    return "floating bodies on a device need body_contact.distance below the support h (the device's rows "
           "of body particles reach h)";
  return {};
}

// The CUDA backend (cuda/*.cu; a build without CUDA throws InputError).
template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_cuda_stepper(const SolverConfig<Dim, Real>& cfg);
// The host-emulated device (host memory through the device API): the CUDA backend's bookkeeping on the CPU.
template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_host_device_stepper(const SolverConfig<Dim, Real>& cfg);

extern template std::unique_ptr<DeviceStepperBase<2, float>> make_cuda_stepper(const SolverConfig<2, float>&);
extern template std::unique_ptr<DeviceStepperBase<2, double>> make_cuda_stepper(
    const SolverConfig<2, double>&);
extern template std::unique_ptr<DeviceStepperBase<3, float>> make_cuda_stepper(const SolverConfig<3, float>&);
extern template std::unique_ptr<DeviceStepperBase<3, double>> make_cuda_stepper(
    const SolverConfig<3, double>&);
extern template std::unique_ptr<DeviceStepperBase<2, float>> make_host_device_stepper(
    const SolverConfig<2, float>&);
extern template std::unique_ptr<DeviceStepperBase<2, double>> make_host_device_stepper(
    const SolverConfig<2, double>&);
extern template std::unique_ptr<DeviceStepperBase<3, float>> make_host_device_stepper(
    const SolverConfig<3, float>&);
extern template std::unique_ptr<DeviceStepperBase<3, double>> make_host_device_stepper(
    const SolverConfig<3, double>&);

}  // namespace cellsph
