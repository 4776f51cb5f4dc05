#pragma once
// The device step (DeviceStepperBase, device_stepper_base.hpp) written once over a memory space: the
// host-emulated device instantiates it with plain g++ (host_device_stepper.cpp), the CUDA backend with
// nvcc (cuda/cuda_steppers_*.cu) after including cuda/cuda_driver.cuh, whose run_pass / reduce_max /
// first_where overloads make every pass below a kernel launch. The passes are the CPU's own (models/,
// boundary/, timestep/, integration/, stability_check.hpp); only the neighbour search differs
// (device_grid.hpp: exact rows, rebuilt every step, no Verlet skin), and it gives the CPU's rows.
//
// The state stays in the space between steps: every field of the particles (DeviceParticles, copied over
// the field list), the solver's per-particle arrays, the rows. One value per step comes back to the host
// (the reduction for dt), plus the stability check's first failing index, the row totals and, with sinks,
// the first fluid index in one (the Simulation then changes the count on the host and uploads again).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/solver/boundary/solid_guard.hpp"
#include "cellsph/solver/boundary/solid_guard_frames.hpp"
#include "cellsph/solver/boundary/wall_motion.hpp"
#include "cellsph/solver/boundary/wall_states.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/device/device_driver.hpp"
#include "cellsph/solver/device/device_grid.hpp"
#include "cellsph/solver/device/device_stepper_base.hpp"
#include "cellsph/solver/device/memory_space.hpp"
#include "cellsph/solver/emitters.hpp"
#include "cellsph/solver/integration/collisions.hpp"
#include "cellsph/solver/models/density_pressure.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/models/model_registry.hpp"
#include "cellsph/solver/models/wcsph.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/stability_check.hpp"

namespace cellsph {

template <int Dim, class Real, class Space>
class DeviceStepper;

// What a model's stepper (models/model_stepper.hpp) sees of a device backend: the DeviceStepper's arrays in
// `Space`, its index sets and rows, the step's input (clock, step number) and its result (timings).
template <int Dim, class Real, class Space>
class DeviceStepContext {
 public:
  template <class T>
  using Array = DeviceArray<T, Space>;
  using Stepper = DeviceStepper<Dim, Real, Space>;

  DeviceStepContext(Stepper& s, const DeviceStepInput<Real>& in, DeviceStepResult<Real>& r, Stopwatch& sw)
      : s_(s), clock_(in.clock), step_(in.step), r_(r), sw_(sw) {}
  [[nodiscard]] const SolverConfig<Dim, Real>& cfg() const { return s_.cfg_; }
  [[nodiscard]] ParticleView<Dim, Real> view() { return s_.view(); }
  [[nodiscard]] DeviceIndexSet<Space> fluid() const { return {s_.fluid_.data(), s_.fluid_.size()}; }
  [[nodiscard]] DeviceIndexSet<Space> fluid_by_pairs() const { return fluid(); }
  [[nodiscard]] DeviceRange<Space> all() const { return DeviceRange<Space>{s_.n_}; }
  [[nodiscard]] std::size_t size() const { return s_.n_; }
  [[nodiscard]] std::size_t fluid_count() const { return s_.fluid_.size(); }
  [[nodiscard]] std::size_t pair_slots() const { return s_.rows_.size(); }
  void density(const ParticleView<Dim, Real>& pv) { fluid_density_pressure(s_.cfg_, pv, fluid()); }
  void wall_states(const ParticleView<Dim, Real>& pv) {
    if (s_.wall_states_)
      cellsph::wall_states(s_.cfg_, pv, DeviceIndexSet<Space>{s_.boundary_.data(), s_.boundary_.size()});
  }
  void body_loads(const ParticleView<Dim, Real>& pv) {
    if (s_.body_slot_.size() > 0) s_.body_forces(pv);
  }
  [[nodiscard]] bool any_tension() const { return s_.any_tension_; }
  [[nodiscard]] bool wall_states_on() const { return s_.wall_states_; }
  [[nodiscard]] Real particle_diameter() const { return s_.diameter_; }
  [[nodiscard]] std::uint64_t step_number() const { return step_; }
  [[nodiscard]] LeapFrogClock<Real>& clock() { return clock_; }
  void forces_done() {
    DeviceOps<Space>::synchronize();
    r_.forces_ms = sw_.ms();
    sw_.reset();
  }
  // One device is one rank: nothing to agree on or share.
  [[nodiscard]] Real agree_dt(Real dt) const { return dt; }
  [[nodiscard]] DfsphOneProcess implicit_exchange() const { return {}; }
  void share_velocity() {}
  template <class A>
  void share(A& /*per_particle*/) {}
  // The Simulation counts a device step's work itself.
  void count_density(std::size_t) {}
  void count_forces(std::size_t) {}
  void count_normals(std::size_t) {}

 private:
  Stepper& s_;
  LeapFrogClock<Real> clock_;
  std::uint64_t step_;
  DeviceStepResult<Real>& r_;
  Stopwatch& sw_;
};

template <int Dim, class Real, class Space>
class DeviceStepper final : public DeviceStepperBase<Dim, Real> {
 public:
  using V = Vec<Dim, Real>;
  template <class T>
  using Array = DeviceArray<T, Space>;
  using Ops = DeviceOps<Space>;

  using Context = DeviceStepContext<Dim, Real, Space>;

  explicit DeviceStepper(const SolverConfig<Dim, Real>& cfg)
      : cfg_(cfg), model_(make_model_stepper<Dim, Real, Context>(cfg_)) {
    const std::string why = device_step_unsupported(cfg_);
    CELLSPH_CHECK(why.empty(), why);
    std::vector<PhaseParams<Real>> params;
    for (const auto& ph : cfg_.phases) {
      params.push_back({ph.rest_density, ph.viscosity, ph.sigma});
      any_tension_ = any_tension_ || ph.sigma > 0;
    }
    phases_.upload(params.data(), params.size());
    planes_.upload(cfg_.planes.data(), cfg_.planes.size());
    guard_boxes_.upload(cfg_.guard.boxes.data(), cfg_.guard.boxes.size());
    guard_grids_.upload(cfg_.guard.grids.data(), cfg_.guard.grids.size());
    guard_values_.upload(cfg_.guard.grid_values.data(), cfg_.guard.grid_values.size());
    motions_.upload(cfg_.wall_motion.motions.data(), cfg_.wall_motion.motions.size());
    motion_rows_.upload(cfg_.wall_motion.rows.data(), cfg_.wall_motion.rows.size());
    std::vector<EmitterPlane<Dim, Real>> emitters;
    for (const Emitter& e : cfg_.inflow.emitters)
      emitters.push_back(emitter_frame<Dim, Real>(e, cfg_.inflow.spacing, double(cfg_.support)));
    emitters_.upload(emitters.data(), emitters.size());
    sinks_.upload(cfg_.inflow.sinks.data(), cfg_.inflow.sinks.size());
  }

  void upload(const Particles<Dim, Real>& p) override {
    upload_particles(p, d_);
    n_ = p.size();
    // What the Simulation derives from the fields (kinds keep their slots; rest density from the phase).
    std::vector<std::uint32_t> fluid, boundary;
    std::vector<Real> rho0(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      (p.kind[i] == ParticleView<Dim, Real>::kFluid ? fluid : boundary)
          .push_back(static_cast<std::uint32_t>(i));
      rho0[i] = cfg_.phases[static_cast<std::size_t>(p.phase[i])].rest_density;
    }
    if (diameter_ == 0) diameter_ = dfsph_particle_diameter<Dim, Real>(p.m.data(), rho0.data(), fluid);
    fluid_.upload(fluid.data(), fluid.size());
    boundary_.upload(boundary.data(), boundary.size());
    fluid_host_ = std::move(fluid);
    row_set_.resize(0);  // the fluid's rows, until upload_bodies
    body_slot_.resize(0);
    rho0_.upload(rho0.data(), n_);
    wall_states_ = cfg_.wall_model != WallModel::Akinci && !boundary.empty();
    for (auto* a : {&vol_, &prho2_}) {
      a->resize(n_);
      a->zero();
    }
    wall_v_.resize(n_);
    wall_v_.zero();
  }

  void upload_wall_self_density(const std::vector<Real>& rho) override {
    CELLSPH_CHECK(rho.size() == n_, "one wall-wall density per particle");
    wall_self_rho_.upload(rho.data(), n_);
  }

  void upload_wall_motion(const std::vector<std::uint32_t>& slot, const std::vector<V>& x0,
                          const std::vector<std::int32_t>& motion, const std::vector<V>& wall_a) override {
    CELLSPH_CHECK(slot.size() == x0.size() && slot.size() == motion.size(), "one entry per moving wall");
    CELLSPH_CHECK(wall_a.empty() || wall_a.size() == n_, "one wall acceleration per particle");
    moving_.upload(slot.data(), slot.size());
    moving_x0_.upload(x0.data(), x0.size());
    moving_motion_.upload(motion.data(), motion.size());
    wall_a_.upload(wall_a.data(), wall_a.size());
  }

  void upload_bodies(const RigidBodySystem<Dim, Real>& b) override {
    const auto& slot = b.slots();
    CELLSPH_CHECK(b.body_of_slot().size() == n_, "one body index per particle");
    body_slot_.upload(slot.data(), slot.size());
    body_of_.upload(b.body_of_body_particle().data(), slot.size());
    body_r0_.upload(b.offsets().data(), slot.size());
    body_of_slot_.upload(b.body_of_slot().data(), n_);
    body_mpp_.upload(b.mass_per_particle().data(), b.mass_per_particle().size());
    body_f_.resize(slot.size());
    body_x_.resize(slot.size());
    contact_ = b.contact_pass({}, body_slot_.data(), body_of_slot_.data(), body_mpp_.data(), body_f_.data());
    // Rows for the fluid and the body particles, ascending.
    std::vector<std::uint32_t> set(fluid_host_.size() + slot.size());
    std::merge(fluid_host_.begin(), fluid_host_.end(), slot.begin(), slot.end(), set.begin());
    row_set_.upload(set.data(), set.size());
  }

  void download_body_forces(std::vector<Vec<Dim, double>>& f, std::vector<V>& x) override {
    f.resize(body_f_.size());
    body_f_.download(f.data());
    run_pass(DeviceRange<Space>{body_slot_.size()},
             GatherPositionsPass<Dim, Real>{d_.x.data(), body_slot_.data(), body_x_.data()});
    x.resize(body_x_.size());
    body_x_.download(x.data());
  }

  void place_bodies(const std::vector<RigidBodyState>& states) override {
    body_states_.upload(states.data(), states.size());
    run_pass(
        DeviceRange<Space>{body_slot_.size()},
        BodyPlacePass<Dim, Real>{d_.x.data(), d_.v.data(), wall_a_.size() > 0 ? wall_a_.data() : nullptr,
                                 body_slot_.data(), body_of_.data(), body_r0_.data(), body_states_.data()});
  }

  void download(Particles<Dim, Real>& p) override { download_particles(d_, p); }

  DeviceStepResult<Real> step(const DeviceStepInput<Real>& in) override {
    DeviceStepResult<Real> r;
    Stopwatch sw;
    build_rows();
    Ops::synchronize();
    r.neighbors_ms = sw.ms();

    sw.reset();
    const DeviceIndexSet<Space> fluid{fluid_.data(), fluid_.size()};
    const bool holding = inflow_mark(in, fluid);
    if (df_kappa_v_.size() != n_) {  // the solver state, where upload_solver_state gave none
      df_kappa_v_.resize(n_);
      df_kappa_v_.zero();
    }
    Context ctx(*this, in, r, sw);
    r.dt = model_->advance(ctx);  // to the drift; the stepper ends the force phase's timing
    r.leapfrog_started = ctx.clock().started;
    if (holding)
      run_pass(fluid, InflowHoldPass<Dim, Real>{d_.x.data(), d_.v.data(), held_.data(), held_x_.data(),
                                                emitters_.data(), r.dt});
    const auto pv = view();
    if (cfg_.box.enabled || !cfg_.planes.empty()) {
      auto walls = box_plane_collisions(cfg_, pv);
      walls.planes = planes_.data();  // the device's copy of cfg.planes
      run_pass(fluid, walls);
    }
    if (cfg_.guard.any()) {
      if (cfg_.guard.moving()) {  // as Simulation::apply_walls: the motions at the step's end
        static const std::vector<RigidBodyState> none;
        const auto frames = guard_frames(cfg_, static_cast<double>(in.time + r.dt), static_cast<double>(r.dt),
                                         in.bodies ? *in.bodies : none);
        guard_frames_.upload(frames.data(), frames.size());
      }
      auto guard = solid_guard(cfg_.guard, pv, guard_frames_.data(),
                               static_cast<std::int32_t>(cfg_.wall_motion.motions.size()), r.dt);
      guard.boxes = guard_boxes_.data();  // the device's copies of cfg.guard's solids
      guard.grids = guard_grids_.data();
      guard.grid_values = guard_values_.data();
      r.guard_corrections = reduce_sum(fluid, guard);
    }
    r.first_bad = first_where(fluid, stability_check(cfg_, pv));
    // The walls where the next step sees them, at the Simulation's new time (time_ += dt, in Real).
    if (moving_.size() > 0) {
      const Real t = in.time + r.dt;
      run_pass(DeviceRange<Space>{moving_.size()},
               MovingWallPass<Dim, Real>{d_.x.data(), d_.v.data(), wall_a_.data(), moving_.data(),
                                         moving_x0_.data(), moving_motion_.data(), motions_.data(),
                                         motion_rows_.data(), static_cast<double>(t)});
    }
    if (sinks_.size() > 0)
      r.first_in_sink =
          first_where(fluid, InflowSinkTest<Dim, Real>{d_.x.data(), sinks_.data(), sinks_.size()});
    Ops::synchronize();
    r.integration_ms = sw.ms();
    return r;
  }

  void upload_solver_state(const SolverState<Dim, Real>& s) override {
    df_kappa_v_.upload(s.dfsph_kappa_v.data(), s.dfsph_kappa_v.size());
  }

  void download_solver_state(SolverState<Dim, Real>& s) override {
    s.dfsph_kappa_v.resize(df_kappa_v_.size());
    df_kappa_v_.download(s.dfsph_kappa_v.data());
  }

  DfsphStats* solver_stats() override { return model_->solver_stats(); }

  DeviceRows neighbor_rows() override {
    build_rows();
    DeviceRows h;
    auto get = [](const auto& dev, auto& host) {
      host.resize(dev.size());
      dev.download(host.data());
    };
    get(offsets_, h.offsets);
    get(count_, h.count);
    get(rows_, h.rows);
    if (wall_states_) {
      get(wall_start_, h.wall_start);
      get(wall_rows_, h.wall_rows);
    }
    return h;
  }

 private:
  friend class DeviceStepContext<Dim, Real, Space>;

  ParticleView<Dim, Real> view() {
    ParticleView<Dim, Real> v;
    v.n = n_;
    attach_particle_fields(v, d_);
    v.rho0 = rho0_.data();
    v.vol = vol_.data();
    v.prho2 = prho2_.data();
    v.wall_v = wall_v_.data();
    v.wall_self_rho = wall_self_rho_.data();
    v.wall_a = wall_a_.size() > 0 ? wall_a_.data() : nullptr;
    v.df_kappa_v = df_kappa_v_.data();
    v.offsets = offsets_.data();
    v.candidates = rows_.data();
    v.within = rows_.data();
    v.within_count = count_.data();
    v.wall_start = wall_start_.data();
    v.wall_nbr = wall_rows_.data();
    v.phases = phases_.data();
    return v;
  }

  // Simulation::inflow_mark: the buffer of the emitters active at the step's start (in.emitters_active, the
  // Simulation's flags); false when none is.
  bool inflow_mark(const DeviceStepInput<Real>& in, const DeviceIndexSet<Space>& fluid) {
    if (in.emitters_active == nullptr) return false;
    emitter_active_.upload(in.emitters_active, emitters_.size());
    held_.resize(n_);
    held_x_.resize(n_);
    run_pass(fluid, InflowMarkPass<Dim, Real>{d_.x.data(), held_.data(), held_x_.data(), emitters_.data(),
                                              emitter_active_.data(), emitters_.size()});
    return true;
  }

  // Simulation::compute_body_loads's passes: each body particle's reaction to its fluid neighbours (the
  // WCSPH pass's own wall term) and its contacts, into body_f_ (summed on the host).
  void body_forces(const ParticleView<Dim, Real>& pv) {
    const DeviceRange<Space> all{body_slot_.size()};
    with_wcsph_forces_pass(cfg_, pv, any_tension_, wall_states_, [&](const auto& pass) {
      using Pass = std::remove_cvref_t<decltype(pass)>;
      run_pass(all, BodyReactionPass<Dim, Real, Pass>{pv, pass, body_slot_.data(), body_f_.data()});
    });
    auto contact = contact_;
    contact.pv = pv;
    run_pass(all, contact);
  }

  // The sorted grid (device_grid.hpp) and the rows of the fluid (and, for wall states, of the walls).
  void build_rows() {
    const DeviceRange<Space> all{n_};
    // Bounding box (a maximum: deterministic), then the grid over it.
    if (identity_.size() != n_) {
      std::vector<std::uint32_t> id(n_);
      for (std::size_t i = 0; i < n_; ++i) id[i] = static_cast<std::uint32_t>(i);
      identity_.upload(id.data(), n_);
    }
    const auto b = reduce_max(DeviceIndexSet<Space>{identity_.data(), n_}, BoundsMax<Dim, Real>{},
                              BoundsPass<Dim, Real>{d_.x.data()});
    GridGeometry<Dim, Real> g;
    g.inv_cell = 1.0 / (static_cast<double>(cfg_.support) * kCellInflation);
    double cells = 1;
    for (int a = 0; a < Dim; ++a) {
      g.lo[a] = -static_cast<double>(b.neg_lo[a]);
      const double extent = double(b.hi[a]) - g.lo[a];
      const double d = std::floor(extent * g.inv_cell) + 1;
      cells *= d;
      if (!(cells <= double(kMaxCells)))
        throw SimulationError("the particles spread over more than " + std::to_string(kMaxCells) +
                              " cells of size h (the device grid's table); a domain bounds them");
      g.dims[a] = static_cast<std::uint32_t>(d);
    }
    const auto ncells = static_cast<std::size_t>(cells);
    int bits = 1;
    while (bits < 32 && (std::size_t{1} << bits) < ncells) ++bits;

    for (auto* a : {&key_, &idx_, &sorted_key_, &sorted_idx_}) a->resize(n_);
    xs_.resize(n_);
    run_pass(all, CellKeyPass<Dim, Real>{g, d_.x.data(), key_.data(), idx_.data()});
    Ops::sort_pairs(key_.data(), idx_.data(), sorted_key_.data(), sorted_idx_.data(), n_, bits, scratch_);
    run_pass(all, GatherPositionsPass<Dim, Real>{d_.x.data(), sorted_idx_.data(), xs_.data()});
    cell_start_.resize(ncells);
    cell_end_.resize(ncells);
    run_pass(DeviceRange<Space>{ncells}, ClearCellsPass{cell_start_.data()});
    run_pass(all, CellBoundsPass{sorted_key_.data(), n_, cell_start_.data(), cell_end_.data()});

    // Fluid rows (all neighbours; with bodies, their particles' rows too) and, for wall states, the wall
    // rows (each wall's fluid neighbours).
    fill_rows(g, row_set_.size() > 0 ? row_set_ : fluid_, false, count_, offsets_, rows_);
    if (wall_states_) fill_rows(g, boundary_, true, wall_count_, wall_start_, wall_rows_);
  }

  // The rows of the particles in `set` over the grid `g`: count, exclusive scan into `offsets`, fill.
  template <class Offset>
  void fill_rows(const GridGeometry<Dim, Real>& g, const Array<std::uint32_t>& set, bool walls,
                 Array<std::uint32_t>& count, Array<Offset>& offsets, Array<std::uint32_t>& rows) {
    count.resize(n_ + 1);
    count.zero();
    offsets.resize(n_ + 1);
    const DeviceIndexSet<Space> indices{set.data(), set.size()};
    GridRowPass<Dim, Real, Offset> rp{g,
                                      d_.x.data(),
                                      d_.h.data(),
                                      d_.kind.data(),
                                      xs_.data(),
                                      sorted_idx_.data(),
                                      cell_start_.data(),
                                      cell_end_.data(),
                                      walls,
                                      count.data(),
                                      nullptr,
                                      nullptr};
    run_pass(indices, rp);
    Ops::exclusive_scan(count.data(), offsets.data(), n_, scratch_);
    rows.resize(static_cast<std::size_t>(offsets.get(n_)));
    rp.offsets = offsets.data();
    rp.rows = rows.data();
    run_pass(indices, rp);
  }

  static constexpr std::size_t kMaxCells = std::size_t{1} << 30;

  SolverConfig<Dim, Real> cfg_;
  std::size_t n_ = 0;
  bool any_tension_ = false;
  bool wall_states_ = false;
  DeviceParticles<Dim, Real, Space> d_;
  Array<PhaseParams<Real>> phases_;
  Array<Plane<Dim, Real>> planes_;
  Array<GuardBox<Dim, Real>> guard_boxes_;
  Array<GuardGrid<Dim, Real>> guard_grids_;
  Array<Real> guard_values_;
  Array<GuardFrame> guard_frames_;  // this step's frames of the moving solids
  Array<std::uint32_t> fluid_, boundary_, identity_;
  std::vector<std::uint32_t> fluid_host_;
  // The model's stepper (models/model_registry.hpp), which owns the arrays only its model reads, and the
  // implicit solvers' CFL length (from the first upload's fluid).
  std::unique_ptr<ModelStepper<Dim, Real, Context>> model_;
  Real diameter_ = 0;
  Array<Real> rho0_, vol_, prho2_, wall_self_rho_;
  Array<Real> df_kappa_v_;  // the solver state (SolverState: DFSPH's divergence warm start)
  Array<V> wall_v_;
  // Moving walls: the config's motions and table rows; per moving wall its slot, initial position, motion;
  // every particle's wall acceleration (empty when nothing moves).
  Array<WallMotion> motions_;
  Array<MotionTableRow> motion_rows_;
  Array<std::uint32_t> moving_;
  Array<V> moving_x0_, wall_a_;
  Array<std::int32_t> moving_motion_;
  // Emitters and sinks (emitters.hpp): the emitters' planes and the sinks (from the config); per emitter
  // whether it is active this step; per particle its emitter or -1 and its start position (the buffer).
  Array<EmitterPlane<Dim, Real>> emitters_;
  Array<Sink> sinks_;
  Array<std::uint8_t> emitter_active_;
  Array<std::int32_t> held_;
  Array<V> held_x_;
  // Floating bodies (boundary/rigid_bodies.hpp): the rows' owners (fluid and body slots; empty: fluid_);
  // per body particle its slot, body, offset, force and gathered position; per particle its body; per
  // body its mass per particle and state; the contact pass with its constants.
  Array<std::uint32_t> row_set_, body_slot_;
  Array<std::int32_t> body_of_, body_of_slot_;
  Array<std::array<double, 3>> body_r0_;
  Array<double> body_mpp_;
  Array<RigidBodyState> body_states_;
  Array<Vec<Dim, double>> body_f_;
  Array<V> body_x_;
  BodyContactPass<Dim, Real> contact_{};
  // The grid and the rows.
  Array<std::uint32_t> key_, idx_, sorted_key_, sorted_idx_, cell_start_, cell_end_;
  Array<V> xs_;
  Array<std::uint32_t> count_, rows_, wall_count_, wall_start_, wall_rows_;
  Array<std::uint64_t> offsets_;
  typename Ops::Bytes scratch_;
};

}  // namespace cellsph
