#pragma once
// The SPH solver: one object owns the particles, the configuration, the neighbour search and the
// components (moving walls, floating bodies, emitters and sinks, the reorder into cell order), and advances
// them by step(), which calls the model's stepper (models/model_stepper.hpp, chosen once by
// models/model_registry.hpp) between what every model shares. Four models (config.model):
//  * PaperMultiphase: Onderik & Durikovic 2007, Algorithm 1 (density eq. 7, Tait, averaged forces eq. 8a-b,
//    colour field and interface tension eq. 8c/9, leap-frog eq. 11): models/paper_stepper.hpp.
//  * Wcsph: the CUDA write-up's weakly compressible SPH with operator splitting and symplectic Euler
//    (models/wcsph_stepper.hpp).
//  * Dfsph: Bender & Koschier's divergence-free SPH, pressure solved implicitly (models/dfsph_stepper.hpp).
//  * Iisph: Ihmsen et al.'s implicit incompressible SPH on DFSPH's passes (models/iisph_stepper.hpp).
//
// Velocities: in the paper's model particles().v holds the leap-frog half-step velocity v(t - dt/2) once
// the first step has run (eq. 11); in the WCSPH model it is v(t).
//
// Determinism: every per-particle sum runs over the canonical CSR row (ascending neighbour index) on one
// thread, so results are bit-identical for any thread count and any neighbour method.
//
// Particle order: every config.reorder_every steps the fluid particles are permuted into cell order
// (Z-order of cells of size h, ties by id) among the fluid slots, so that the pair loops read
// neighbours close in memory; with reordering on, the boundary particles are put in that order once at
// construction. Kinds therefore keep their slots (fluid slots stay fluid), but particles() is in this
// internal order: index i names a particle only until the next reorder. Follow a particle by its
// particles().id (a permutation of 0..n-1, the input order unless given); copy_in_id_order()
// (particles.hpp) gives the input order back, and the frame writers use it. The reorder schedule
// depends only on the step count (or the clock, with per-particle steps) and the key only on
// positions and ids, so results stay independent of the method, the skin and the thread count, and a
// checkpoint (which holds the permuted order and the ids) resumes bit for bit.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/solver/backend.hpp"
#include "cellsph/solver/boundary/moving_walls.hpp"
#include "cellsph/solver/boundary/rigid_bodies.hpp"
#include "cellsph/solver/boundary/wall_neighbors.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/device/device_stepper_base.hpp"
#include "cellsph/solver/inflow_outflow.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/models/model_stepper.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/particles.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

namespace distributed {
class Communicator;
template <int Dim, class Real>
class RankDomain;
}  // namespace distributed

// Wall-clock time spent in each phase of step(), accumulated over all steps [ms].
struct StepTimings {
  double neighbors = 0;           // building the search structure and the CSR lists
  double forces = 0;              // density, pressure, forces
  double integration = 0;         // time step choice, integration, walls, stability check
  std::uint64_t list_builds = 0;  // neighbour searches run (Verlet lists are kept between them)
  std::uint64_t bare_builds = 0;  // of which at the bare supports (skinned lists did not last a step)
  double reorder = 0;             // permuting the particles into cell order (config reorder_every)
  std::uint64_t reorders = 0;     // reorders run
  // Work done, in particles (summed over steps): a global step evaluates every fluid particle once; a
  // per-particle sub-step only the particles it integrates and those their forces read.
  std::uint64_t density_evals = 0;  // densities and pressures (eq. 7 + equation of state)
  std::uint64_t normal_evals = 0;   // CSF colour normals
  std::uint64_t force_evals = 0;    // forces (eq. 8-9)
};

// A run across ranks (Simulation::distribute): how its domain went.
struct RankStats {
  int ranks = 1;
  std::uint64_t rebuilds = 0;    // particles moved to their owners and the halo built again
  std::uint64_t rebalances = 0;  // the curve cut again by the measured work
  double imbalance = 0;          // at the last rebuild: the busiest rank's work over the mean, less 1
  double max_imbalance = 0;      // the largest of those
};

// What step() carries from one step to the next besides the particles.
template <class Real>
struct IntegratorState {
  Real time = 0;                  // simulated time [s]
  Real last_dt = 0;               // the last step's dt (the paper model's leap-frog needs it)
  std::uint64_t steps = 0;        // steps taken
  bool leapfrog_started = false;  // paper model: particles().v holds v(t - dt/2)
  // Emitters and sinks (emitters.hpp): the id the next emitted particle gets (0 on restore: the largest
  // id + 1) and, per emitter, the distance its newest layer has travelled (empty on restore: as at t = 0).
  std::uint64_t next_id = 0;
  std::vector<double> emitter_advance{};
};

template <int Dim, class Real>
class HostStepContext;  // simulation.cpp: what a model's stepper sees of the CPU backend

template <int Dim, class Real>
class Simulation {
 public:
  using V = Vec<Dim, Real>;
  using Config = SolverConfig<Dim, Real>;

  // Validates the config (InputError) and completes the particles: x, v, m, phase, kind and id are the
  // inputs (id may be left empty or all 0: the input order; otherwise it must be a permutation of
  // 0..n-1; v, kind may be left empty: zero velocity, all fluid; m may be left empty or 0 for a fluid
  // particle: the phase's mass). support, colour and viscosity are set from the config and the phase table,
  // density to the rest density (with the continuity density, a fluid particle's positive, finite input
  // density is kept as its initial density); boundary particles with m == 0 get their Akinci weight psi_b in
  // m (a positive m is kept: for walls sampled on the fluid's lattice, several support lengths thick, m =
  // rho0 spacing^Dim makes the wall look exactly like fluid).
  Simulation(Config config, Particles<Dim, Real> particles);
  ~Simulation();
  Simulation(Simulation&&);
  Simulation& operator=(Simulation&&);

  // One time step of the configured model (with per-particle steps: advances the particles whose own
  // time is the global clock, then the clock to the next such time). Throws SimulationError (step, particle,
  // quantity, value) when a particle's state is not finite or leaves the domain.
  void step();
  // Steps until time() >= t_end (the last step is not shortened).
  void run_until(Real t_end);

  [[nodiscard]] Real time() const { return time_; }
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  // Fluid particles put back out of a wall or obstacle they would have ended a step inside, since this
  // Simulation was made (boundary/solid_guard.hpp; not checkpointed: a resume counts from 0).
  [[nodiscard]] std::uint64_t wall_corrections() const { return wall_corrections_; }
  [[nodiscard]] Real last_dt() const { return clock_.last_dt; }
  // In the internal (cell) order: see "Particle order" above; particles().id names each particle.
  // With a device backend the particles are copied back here, only when the device holds newer ones
  // (at output and checkpoint times).
  // In a run across ranks (distribute()), the particles of the last gather_for_output(): every particle on
  // rank 0, in id order, none on the other ranks.
  [[nodiscard]] const Particles<Dim, Real>& particles() const {
    if (domain_) return shown_;
    sync_host();
    return p_;
  }
  [[nodiscard]] const Config& config() const { return cfg_; }
  [[nodiscard]] const StepTimings& timings() const { return timings_; }
  [[nodiscard]] const SearchStats& search_stats() const { return search_.stats(); }
  // Over every rank in a run across ranks.
  [[nodiscard]] std::size_t fluid_count() const { return domain_ ? global_fluid_count_ : fluid_count_; }
  // Model::Dfsph and Model::Iisph: iterations and errors of the pressure solves (models/dfsph.hpp,
  // iisph.hpp); all 0 for the explicit models.
  [[nodiscard]] const DfsphStats& dfsph_stats() const;
  // The same, null for the explicit models.
  [[nodiscard]] const DfsphStats* solver_stats() const;
  // What the model's stepper shows of the run (models/model_stepper.hpp): its part of the progress line
  // ("" for none) and its summary lines (the implicit solves' sweeps, errors and where a step's time goes).
  [[nodiscard]] std::string solver_progress() const;
  [[nodiscard]] std::vector<std::string> solver_summary() const;

  // Diagnostics over fluid particles.
  [[nodiscard]] V momentum() const;
  [[nodiscard]] Real kinetic_energy() const;
  [[nodiscard]] Real total_mass() const;

  // Checkpoints (written by io/simulation_checkpoint.hpp): the particles (every field of the field list),
  // the solver state (the same order) and this integrator state. Restoring the three into a Simulation
  // built from the same config and continuing gives results bit-identical to an uninterrupted run.
  [[nodiscard]] const SolverState<Dim, Real>& solver_state() const {
    if (domain_) return shown_state_;
    sync_host();
    return state_;
  }
  [[nodiscard]] IntegratorState<Real> integrator_state() const {
    return {time_, clock_.last_dt, steps_, clock_.started, inflow_.next_id(), inflow_.advance()};
  }
  // Replaces the particles and the integrator state. Throws InputError, prefixed with `source` (the
  // checkpoint file), when the particles do not fit this simulation: count (any count with emitters or
  // sinks; ids then unique and below the state's next id rather than a permutation), phase or kind not in its
  // tables, ids not a permutation, values no run holds (non-finite, support <= 0, time-step level or tick
  // out of range, non-finite or negative time). The simulation is untouched on those errors; with dynamic
  // walls, positions beyond what the neighbour search indexes are found after the particles were
  // replaced (InputError too; the simulation must not be stepped then). The particles keep their
  // order (a checkpoint holds the internal order, so a resume is bit for bit). `solver`: the solver
  // state, in the particles' order (its fields empty: 0, as for a run that starts).
  void restore(Particles<Dim, Real> particles, const IntegratorState<Real>& state, const std::string& source,
               SolverState<Dim, Real> solver = {});

  // Floating bodies (boundary/rigid_bodies.hpp): each body's state (centre, orientation, velocities) and
  // the fluid and contact force and torque of the last step. A checkpoint holds the states
  // (io/simulation_checkpoint.hpp); restore_bodies puts them back after restore() (InputError naming
  // `source` when they do not fit the scene's bodies).
  [[nodiscard]] const std::vector<RigidBodyState>& body_states() const { return bodies_.states(); }
  [[nodiscard]] const std::vector<RigidBodyLoad>& body_loads() const { return bodies_.loads(); }
  // Per particle slot (particles()' order), its body or -1; empty without bodies.
  [[nodiscard]] const std::vector<std::int32_t>& body_of_slot() const { return bodies_.body_of_slot(); }
  void restore_bodies(std::vector<RigidBodyState> states, const std::string& source);

  // Per-particle steps, for tests and benchmarks: true computes the densities (and CSF normals) of every
  // fluid particle in every sub-step instead of only those the due particles' forces read. Results are
  // bit-identical either way (only the densities of particles no force reads differ: with the work sets they
  // keep the value of their last evaluation); only the cost changes.
  void set_full_passes(bool on) { full_passes_ = on; }

  // The backend of the following steps (backend.hpp). Cpu (the default) steps here; Cuda and HostDevice
  // copy the particles to the device, which from then on holds the state between steps
  // (solver/device/). Throws InputError when the backend is not available (require_backend) or does not
  // support this config (the device step: WCSPH with global steps, Akinci or Adami walls, no reorder).
  // Switching back to Cpu copies the particles back. Results: bit-identical to the CPU through
  // HostDevice; within rounding on a GPU (docs/gpu.md).
  void use_backend(Backend b);
  [[nodiscard]] Backend backend() const { return backend_; }

  // One run across the ranks of `comm` (docs/distributed.md): called on every rank, after construction (and
  // a resume's restore) from the same particles, it keeps on this rank the particles it owns (a range of the
  // curve, distributed/rank_domain.hpp) and the copies its rows need; each step then moves particles to
  // their owners and exchanges what the passes share, and every particle gets the bits of the
  // single-process run (`neighbors.reorder_every` 0: the id order). Throws InputError, naming the key,
  // for what the step across ranks does not run yet (global steps on the CPU, every model but DFSPH's CG
  // solve, without volume-map walls, emitters and reordering). One rank: nothing changes.
  void distribute(const distributed::Communicator& comm);
  [[nodiscard]] bool distributed() const { return domain_ != nullptr; }
  // A run across ranks: its ranks, rebuilds of the domain, rebalances and the work's imbalance (the same on
  // every rank).
  [[nodiscard]] const RankStats& rank_stats() const { return rank_stats_; }
  // A run across ranks: collective (every rank calls it at the same point): particles() and
  // solver_state() then hold every particle on rank 0 (the outputs' and checkpoints' source). Otherwise
  // nothing.
  void gather_for_output();

 private:
  friend class HostStepContext<Dim, Real>;
  // Construction's parts: the particles' fields completed (returns the input densities a continuity run
  // starts from), then checked against the phase and kind tables and given their phases' values.
  std::vector<Real> complete_fields();
  void set_phase_values(const std::vector<Real>& rho_in);
  // restore()'s checks of a checkpoint (InputError prefixed with `source`): its count and ids (returns
  // the next id of its emitters), then the values no run holds.
  std::uint64_t check_restored_ids(const Particles<Dim, Real>& particles, const IntegratorState<Real>& state,
                                   const std::string& source) const;
  void check_restored_values(const Particles<Dim, Real>& particles, SolverState<Dim, Real>& solver,
                             const IntegratorState<Real>& state, const std::string& source) const;
  // The plain view of every per-particle array the passes read (particle_view.hpp). Built afresh for each
  // pass: it holds the arrays' current addresses, which change when an array is resized or swapped.
  ParticleView<Dim, Real> view();
  // boundary_rows: also the rows of boundary particles (their weights need them); a step needs only
  // fluid rows, so boundary particles are then searched with support 0.
  void compute_neighbors(bool boundary_rows = false);
  using IndexList = IndexSet;
  // The pairs of the rows of `set` within h (the Verlet lists hold h + skin): view().row_begin(i) ..
  // row_end(i).
  void filter_lists(const IndexList& set);
  // The passes run over a set of fluid particles (ascending indices): fluid_ for a global step. Each runs
  // the pass of the file named in its definition through the driver (pass_driver.hpp).
  void compute_density_pressure(const IndexList& set);
  // The per-particle arrays every model reads sized for this step, and with Adami or dynamic walls each
  // wall particle's fluid neighbours gathered from the fluid rows (boundary/wall_neighbors.hpp), so
  // that the view a stepper takes stays valid through the step.
  void prepare_shared_arrays();
  // The floating bodies' loads from the force pass's wall term (WCSPH).
  void compute_body_loads(const ParticleView<Dim, Real>& pv);
  // Host: the fluid split between the threads by row length, for the implicit solvers' sweeps.
  const BalancedIndexSet& fluid_by_pairs();
  void apply_walls(Real dt);
  void check_state();
  [[noreturn]] void report_unstable(std::int64_t first) const;
  [[noreturn]] void report_diverged_solve(const SimulationError& e);
  [[nodiscard]] std::string describe_unstable(std::int64_t first) const;
  void step_device();
  void upload_to_device();
  void sync_host() const;
  void init_boundary_weights();
  void build_wall_map();
  // Moving walls (boundary/moving_walls.hpp): their slots from the particles' ids (set_moving_slots), and
  // their state at time t (move_walls: position, velocity, acceleration).
  void set_moving_slots();
  void move_walls(Real t);
  // Floating bodies: their slots (from the ids) and their particles' search radius (the contact distance,
  // so that their rows hold the walls they touch).
  void set_body_slots(bool place);
  // Their step of dt (then their particles are placed; SimulationError when a state is not finite).
  void advance_bodies(Real dt);
  void step_per_particle();
  // The particles of `slots` (ascending indices of one kind) reordered among those slots by cell key,
  // ties by id; every per-particle array is permuted and the Verlet lists invalidated.
  void reorder_slots(const IndexList& slots);
  // Emitters and sinks (inflow_outflow.hpp) at the end of a step: the layers due emitted and the sinks'
  // particles removed. maybe_in_sink: false when the device found no fluid particle in a sink (the count
  // then changes only when a layer is due; with a device backend a change copies the particles here and
  // back).
  void inflow_end_step(Real dt, bool maybe_in_sink);
  // Removes the particles with keep[i] == 0 (stable; keep empty: none) and appends `added` particles
  // (zero-filled, for the caller to set), in every per-particle array; rebuilds the kind lists.
  void change_count(const std::vector<std::uint8_t>& keep, std::size_t added);
  void rebuild_kind_lists();
  // A run across ranks: the particles to their owners and the halo again (first: the start's split);
  // the kind lists then hold the owned particles, local_fluid_ every fluid particle here.
  void rebuild_domain(bool first);
  // Each step across ranks: the domain rebuilt when a particle has moved more than its margin allows
  // (every rank agrees), else the halo copies' positions and velocities refreshed.
  void update_domain();
  // The work of the particles this rank owns (the split's weights), and the curve cut again by it when the
  // busiest rank's exceeds the mean by more than rebalance_threshold.
  [[nodiscard]] std::int64_t owned_work(std::size_t i) const;
  void balance_domain();
  void check_distributable() const;
  // The fluid whose rows a step builds: every local one in a run across ranks (halo copies too: the walls'
  // fluid neighbours are gathered from them), else fluid_.
  [[nodiscard]] const IndexList& row_fluid() const { return domain_ ? local_fluid_ : fluid_; }
  // After a pass wrote fields of the owned particles: the halo copies refreshed (a run across ranks).
  void share_density();
  void share_wall_states();
  void share_velocity();
  // Floating bodies across ranks: every rank's body particles' forces summed in id order on every rank (the
  // single-process sums), so that each rank steps the same bodies.
  void share_body_loads();
  [[nodiscard]] std::string unstable_message(std::int64_t first) const;

  Config cfg_;
  // Mutable: with a device backend, particles() (const) copies the device's newer state back here.
  mutable Particles<Dim, Real> p_;
  Backend backend_ = Backend::Cpu;
  std::unique_ptr<DeviceStepperBase<Dim, Real>> device_;  // null on the CPU
  mutable bool host_stale_ = false;                       // the device holds newer particles than p_
  NeighborSearch<Dim, Real> search_;
  NeighborList nl_;
  std::vector<std::uint32_t> within_;  // filter_lists: row i at nl_.offsets[i], within_count_[i] long
  std::vector<std::uint32_t> within_count_;
  // The model's stepper (models/model_registry.hpp), which owns the arrays only its model reads.
  std::unique_ptr<ModelStepper<Dim, Real, HostStepContext<Dim, Real>>> stepper_;
  std::vector<V> normal_;                        // per-particle steps: the CSF colour normals of the sub-step
  std::vector<Real> rho0_;                       // rest density per particle (from its phase)
  std::vector<PhaseParams<Real>> phase_params_;  // cfg_.phases as the passes read them
  // Per fluid particle, from the density pass, so pair loops divide once per particle, not per pair.
  std::vector<Real> vol_;    // V_j = m_j / rho_j
  std::vector<Real> prho2_;  // p_j / rho_j^2 (WCSPH symmetric pressure)
  std::vector<V> xs_;        // per-particle steps: every position extrapolated to the global clock
  // Per-particle steps, the work sets of a sub-step (ascending): the particles integrated (their forces
  // are evaluated), those whose CSF normals and whose densities those forces read.
  IndexList due_list_, normal_set_, rho_set_;
  std::vector<std::uint8_t> mark_;  // per particle: 1 density needed, 2 normal needed
  bool full_passes_ = false;
  // Indices of the boundary particles, ascending; fixed for a simulation like fluid_ (set with it).
  IndexList boundary_;
  // Adami and dynamic walls, rebuilt every step (nothing kept across steps, so the particle arrays may be
  // reordered): the fluid neighbours of each boundary particle (boundary/wall_neighbors.hpp) and the
  // extrapolated wall velocity of the no-slip term.
  WallNeighbors walls_;
  std::vector<V> wall_v_;
  // WallModel::Dynamic: sum_c m_c W_wc over the wall particles c within h of wall w (w itself included),
  // the constant part of w's summation density (walls never move); 0 for fluid slots.
  std::vector<Real> wall_self_rho_;
  // Indices of the fluid particles, ascending. Kinds never change, and reordering permutes particles
  // only among the slots of their own kind, so this list is fixed for a simulation.
  std::vector<std::uint32_t> fluid_;
  // Verlet lists: the step's CSR lists hold the pairs within h + skin of the positions x_built_ and are
  // kept while no particle has moved more than 0.45 skin since (then every pair within h now was
  // within h + skin then: triangle inequality). Each step filter_lists() cuts the rows to the pairs
  // with distance2(x_i, x_j) <= h_i^2, the search's own test, so each sum runs over exactly the neighbours
  // an exact search gives, in the same (ascending) order: results do not depend on the skin, the
  // rebuild schedule, the method or a resume.
  std::vector<Real> search_h_;  // support per particle for the lists: h + skin (0 for boundary)
  std::vector<V> x_built_;      // positions the lists were built from
  Real skin_ = 0;
  bool lists_valid_ = false;
  // Steps the current lists have been kept; when skinned lists do not last one step, the next
  // kBareSearches searches run at the bare supports (bare_h_: h for fluid, the bodies' radius, 0 for walls;
  // kept beside search_h_, not computed as search_h_ less the skin, which can round below h), whose rows hold
  // the same pairs within h. The schedule changes the speed only, never a result.
  std::uint32_t lists_kept_ = 0;
  std::uint32_t bare_searches_ = 0;
  static constexpr std::uint32_t kBareSearches = 16;
  std::vector<Real> bare_h_;
  // The last search ran at the bare supports (or without a skin): its rows hold exactly the pairs within h,
  // so filter_lists() only counts them and the passes read the candidates (verlet_rows.hpp).
  bool rows_at_h_ = false;
  bool any_tension_ = false;
  // WallModel::Adami or Dynamic and there are boundary particles: walls carry their own p, rho (and
  // velocity for no slip), computed each step by compute_wall_states.
  bool wall_states_ = false;
  std::size_t fluid_count_ = 0;

  // Integrator state (integrator_state(), restore()).
  Real time_ = 0;
  LeapFrogClock<Real> clock_;  // the last step, and whether v holds v(t - dt/2) (the paper's leap-frog)
  std::uint64_t steps_ = 0;
  std::uint64_t wall_corrections_ = 0;

  StepTimings timings_;

  // Moving walls (config wall_motion, boundary/moving_walls.hpp), and each wall particle's acceleration
  // (moving walls and floating bodies set it, Adami's pressure reads it; empty when nothing moves).
  MovingWalls<Dim, Real> moving_;
  std::vector<V> wall_a_;
  // Floating bodies (config rigid_bodies): their particles' slots, offsets, states and loads; with a device
  // backend, per body particle the force and position the device computed in the step.
  RigidBodySystem<Dim, Real> bodies_;
  std::vector<Vec<Dim, double>> body_f_;
  std::vector<V> body_x_;

  // State carried from step to step that is not a particle field (solver_state(); permuted by reorders,
  // in checkpoints): the DFSPH divergence solve's accumulated k, its next warm start.
  mutable SolverState<Dim, Real> state_;  // mutable: copied back from a device with the particles
  Real particle_diameter_ = 0;            // the implicit solvers' CFL length (once, from the fluid)
  // DFSPH's passes run over the fluid split between the threads by row length (pass_driver.hpp), rebuilt
  // each step. A particle's own loads and stores weigh about as much as four pairs' (a pair reads 16
  // bytes in order and gathers one or three values; a particle some 60 bytes).
  BalancedIndexSet fluid_split_;
  static constexpr std::uint64_t kBalanceParticleWeight = 4;

  // Emitters and sinks (config inflow): the component with its buffer and its part of the integrator state.
  EmittersAndSinks<Dim, Real> inflow_;

  // A run across ranks (distribute()): this rank's domain, the fluid held here (owned and halo), the
  // gathered particles the outputs read, and the fluid count over every rank. Null otherwise.
  std::unique_ptr<distributed::RankDomain<Dim, Real>> domain_;
  IndexList local_fluid_, local_walls_;
  Particles<Dim, Real> shown_;
  SolverState<Dim, Real> shown_state_;
  std::size_t global_fluid_count_ = 0;
  std::vector<V>
      x_domain_;  // positions at the domain's last rebuild (its halo's margin is measured from them)
  Real domain_margin_ = 0;  // the halo's reach beyond the support
  RankStats rank_stats_;
};

extern template class Simulation<2, float>;
extern template class Simulation<2, double>;
extern template class Simulation<3, float>;
extern template class Simulation<3, double>;

}  // namespace cellsph
