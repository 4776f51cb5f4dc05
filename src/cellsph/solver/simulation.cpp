#include "cellsph/solver/simulation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/distributed/rank_domain.hpp"  // the domain_ of a run across ranks
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/boundary/akinci2012.hpp"
#include "cellsph/solver/boundary/bender2019.hpp"
#include "cellsph/solver/boundary/dynamic_crespo2007.hpp"
#include "cellsph/solver/boundary/solid_guard.hpp"
#include "cellsph/solver/boundary/solid_guard_frames.hpp"
#include "cellsph/solver/boundary/wall_neighbors.hpp"
#include "cellsph/solver/boundary/wall_states.hpp"
#include "cellsph/solver/cell_order.hpp"
#include "cellsph/solver/integration/collisions.hpp"
#include "cellsph/solver/models/continuity_density.hpp"
#include "cellsph/solver/models/density_pressure.hpp"
#include "cellsph/solver/models/model_registry.hpp"
#include "cellsph/solver/models/paper_stepper.hpp"
#include "cellsph/solver/models/wcsph.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/stability_check.hpp"
#include "cellsph/solver/timestep/global_courant.hpp"
#include "cellsph/solver/timestep/per_particle_levels.hpp"
#include "cellsph/solver/verlet_rows.hpp"

namespace cellsph {

namespace {

constexpr std::uint8_t kFluid = static_cast<std::uint8_t>(ParticleKind::Fluid);
constexpr std::uint8_t kBoundary = static_cast<std::uint8_t>(ParticleKind::Boundary);

// Empty when `id` is a permutation of 0..n-1, otherwise what is wrong with it.
std::string id_permutation_error(const std::vector<std::uint32_t>& id) {
  std::vector<std::uint8_t> seen(id.size(), 0);
  for (std::size_t i = 0; i < id.size(); ++i) {
    if (id[i] >= id.size() || seen[id[i]]) {
      std::ostringstream os;
      os << "particle " << i << " has id " << id[i]
         << (id[i] >= id.size() ? " (ids must be below the particle count " + std::to_string(id.size()) + ")"
                                : " (another particle has it too)");
      return os.str();
    }
    seen[id[i]] = 1;
  }
  return {};
}

// The step's search: the wall particles search with support 0 (search_h_) and no pass reads their rows,
// so Cell Indexing leaves them empty instead of searching them.
SearchOptions step_search(SearchOptions o) {
  o.zero_support_rows = false;
  return o;
}

// What the implicit solvers' step shares beyond this rank's particles (models/dfsph.hpp's DfsphOneProcess
// names each call): the halo copies of what a pass wrote, the solves' errors and the step over every rank.
template <int Dim, class Real>
struct RankExchange {
  const distributed::RankDomain<Dim, Real>* domain;  // null: one process
  std::size_t fluid;                                 // the fluid particles over every rank
  void density(const ParticleView<Dim, Real>& pv) const {
    if (domain) domain->refresh(pv.rho, pv.vol, pv.df_kappa, pv.df_mk);
  }
  void k(const ParticleView<Dim, Real>& pv) const {
    if (domain) domain->refresh(pv.df_kappa, pv.df_mk);
  }
  void v(const ParticleView<Dim, Real>& pv) const {
    if (domain) domain->refresh(pv.v, pv.df_mv);
  }
  [[nodiscard]] Real min(Real dt) const { return domain ? domain->min(dt) : dt; }
  template <class Set, class Pass>
  [[nodiscard]] double mean(const Set& set, const Pass& pass) const {
    if (!domain) return DfsphOneProcess{}.mean(set, pass);
    const IndexSet& s = set_of(set);
    const ExactSum local = reduce_sum_exact_n(s.data(), s.size(), pass);
    return domain->comm().sum(local).value() / static_cast<double>(std::max<std::size_t>(fluid, 1));
  }
  static const IndexSet& set_of(const IndexSet& s) { return s; }
  static const IndexSet& set_of(const BalancedIndexSet& s) { return *s.set; }
};

}  // namespace

// What a model's stepper (models/model_stepper.hpp) sees of the CPU backend: the Simulation's arrays, the
// fluid's index list (and its split by row length), the wall states and floating bodies' loads, the
// leap-frog clock and the step's timings.
template <int Dim, class Real>
class HostStepContext {
 public:
  template <class T>
  using Array = std::vector<T>;

  HostStepContext(Simulation<Dim, Real>& s, Stopwatch& sw) : s_(s), sw_(sw) {}
  [[nodiscard]] const SolverConfig<Dim, Real>& cfg() const { return s_.cfg_; }
  [[nodiscard]] ParticleView<Dim, Real> view() { return s_.view(); }
  [[nodiscard]] const IndexSet& fluid() const { return s_.fluid_; }
  [[nodiscard]] const BalancedIndexSet& fluid_by_pairs() { return s_.fluid_by_pairs(); }
  [[nodiscard]] std::size_t all() const { return s_.p_.size(); }
  [[nodiscard]] std::size_t size() const { return s_.p_.size(); }
  [[nodiscard]] std::size_t fluid_count() const { return s_.fluid_.size(); }
  [[nodiscard]] std::size_t pair_slots() const { return s_.nl_.indices.size(); }
  void density(const ParticleView<Dim, Real>& pv) {
    fluid_density_pressure(s_.cfg_, pv, s_.fluid_);
    s_.share_density();
  }
  void wall_states(const ParticleView<Dim, Real>& pv) {
    if (!s_.wall_states_) return;
    cellsph::wall_states(s_.cfg_, pv, s_.boundary_);
    s_.share_wall_states();
  }
  void body_loads(const ParticleView<Dim, Real>& pv) {
    if (s_.bodies_.any()) s_.compute_body_loads(pv);
  }
  [[nodiscard]] bool any_tension() const { return s_.any_tension_; }
  [[nodiscard]] bool wall_states_on() const { return s_.wall_states_; }
  [[nodiscard]] Real particle_diameter() {
    if (s_.particle_diameter_ == 0) {
      s_.particle_diameter_ = dfsph_particle_diameter(s_.view(), s_.fluid_);
      if (s_.domain_)  // over every rank (one that owns no fluid has none)
        s_.particle_diameter_ =
            s_.domain_->min(s_.fluid_.empty() ? std::numeric_limits<Real>::max() : s_.particle_diameter_);
    }
    return s_.particle_diameter_;
  }
  [[nodiscard]] std::uint64_t step_number() const { return s_.steps_ + 1; }
  [[nodiscard]] LeapFrogClock<Real>& clock() { return s_.clock_; }
  [[nodiscard]] Real agree_dt(Real dt) const { return s_.domain_ ? s_.domain_->min(dt) : dt; }
  [[nodiscard]] RankExchange<Dim, Real> implicit_exchange() const {
    return {s_.domain_.get(), s_.fluid_count()};
  }
  void share_velocity() { s_.share_velocity(); }
  template <class T>
  void share(std::vector<T>& per_particle) {
    if (s_.domain_) s_.domain_->refresh(per_particle);
  }
  void forces_done() {
    s_.timings_.forces += sw_.ms();
    sw_.reset();
  }
  void count_density(std::size_t n) { s_.timings_.density_evals += n; }
  void count_forces(std::size_t n) { s_.timings_.force_evals += n; }
  void count_normals(std::size_t n) { s_.timings_.normal_evals += n; }

 private:
  Simulation<Dim, Real>& s_;
  Stopwatch& sw_;
};

// The particles' inputs completed (those that may be left empty get their defaults; any other size
// mismatch is an InputError) and the fields the Simulation sets cleared. Returns the input densities a
// continuity run starts from (empty otherwise).
template <int Dim, class Real>
std::vector<Real> Simulation<Dim, Real>::complete_fields() {
  const std::size_t n = p_.x.size();
  auto complete = [n](auto& field, const char* name, auto value) {
    if (field.empty()) field.assign(n, value);
    if (field.size() != n) {
      std::ostringstream os;
      os << "particles: field '" << name << "' has " << field.size() << " entries, positions have " << n;
      throw InputError(os.str());
    }
  };
  complete(p_.v, "velocity", V{});
  complete(p_.m, "mass", Real(0));
  complete(p_.phase, "phase", std::int32_t{0});
  complete(p_.kind, "kind", kFluid);
  p_.f.assign(n, V{});
  // The continuity equation carries the density: a positive, finite input density of a fluid particle is
  // its initial density (the scene's hydrostatic start gives each the state equation's density for its
  // depth); otherwise, and always with summation density, the phase's rest density.
  const bool carried_density = cfg_.density_evolution == DensityEvolution::Continuity;
  std::vector<Real> rho_in;
  if (carried_density && p_.rho.size() == n) rho_in = std::move(p_.rho);
  p_.rho.assign(n, Real(0));
  p_.p.assign(n, Real(0));
  p_.h.assign(n, cfg_.support);
  p_.color.assign(n, Real(0));
  p_.mu.assign(n, Real(0));
  complete(p_.level, "level", std::int32_t{0});
  complete(p_.tick, "tick", std::int64_t{0});
  // Ids: empty, or all 0 as left by builders that resize the field list, mean the input order.
  if (std::all_of(p_.id.begin(), p_.id.end(), [](std::uint32_t k) { return k == 0; })) p_.id.clear();
  if (p_.id.empty()) {
    CELLSPH_CHECK(n <= std::numeric_limits<std::uint32_t>::max(), n << " particles do not fit 32-bit ids");
    p_.id.resize(n);
    for (std::size_t i = 0; i < n; ++i) p_.id[i] = static_cast<std::uint32_t>(i);
  }
  complete(p_.id, "id", std::uint32_t{0});
  if (const auto err = id_permutation_error(p_.id); !err.empty()) throw InputError("particles: " + err);
  return rho_in;
}

// Each particle checked against the phase and kind tables, and given its phase's rest density, colour,
// viscosity and (fluid without one) mass.
template <int Dim, class Real>
void Simulation<Dim, Real>::set_phase_values(const std::vector<Real>& rho_in) {
  const std::size_t n = p_.x.size();
  fluid_count_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto ph = p_.phase[i];
    if (ph < 0 || static_cast<std::size_t>(ph) >= cfg_.phases.size()) {
      std::ostringstream os;
      os << "particles: particle " << i << " has phase " << ph << ", the phase table has "
         << cfg_.phases.size() << " entries";
      throw InputError(os.str());
    }
    if (p_.kind[i] != kFluid && p_.kind[i] != kBoundary) {
      std::ostringstream os;
      os << "particles: particle " << i << " has kind " << int(p_.kind[i]) << " (0 fluid, 1 boundary)";
      throw InputError(os.str());
    }
    if (!all_finite(p_.x[i]) || !all_finite(p_.v[i])) {
      std::ostringstream os;
      os << "particles: particle " << i << " has a non-finite position or velocity";
      throw InputError(os.str());
    }
    const auto& phase = cfg_.phases[static_cast<std::size_t>(ph)];
    rho0_[i] = phase.rest_density;
    p_.rho[i] = phase.rest_density;
    if (!rho_in.empty() && p_.kind[i] == kFluid && std::isfinite(rho_in[i]) && rho_in[i] > 0)
      p_.rho[i] = rho_in[i];
    p_.color[i] = phase.color;
    p_.mu[i] = phase.viscosity;
    if (p_.kind[i] == kFluid) {
      ++fluid_count_;
      if (p_.m[i] <= 0) p_.m[i] = phase.mass;
      if (!(p_.m[i] > 0 && std::isfinite(p_.m[i]))) {
        std::ostringstream os;
        os << "particles: fluid particle " << i << " has mass " << p_.m[i] << " and phase '" << phase.name
           << "' gives none (phases[" << ph << "].mass)";
        throw InputError(os.str());
      }
    } else {
      p_.v[i] = V{};
      if (!(p_.m[i] >= 0 && std::isfinite(p_.m[i]))) {
        std::ostringstream os;
        os << "particles: boundary particle " << i << " has weight (mass) " << p_.m[i];
        throw InputError(os.str());
      }
    }
  }
}

template <int Dim, class Real>
Simulation<Dim, Real>::Simulation(Config config, Particles<Dim, Real> particles)
    : cfg_(std::move(config)), p_(std::move(particles)), search_(step_search(cfg_.search)) {
  cfg_.validate();
  for (const auto& ph : cfg_.phases) phase_params_.push_back({ph.rest_density, ph.viscosity, ph.sigma});
  const std::size_t n = p_.x.size();
  const std::vector<Real> rho_in = complete_fields();
  rho0_.assign(n, Real(0));
  state_.assign_zero(n);
  inflow_.init(cfg_, n);
  // Moving walls: each particle's motion and initial position, kept by id (the input order's index is
  // lost when the boundary is reordered below).
  moving_.init(cfg_.wall_motion, p_.x, p_.kind, p_.id, kBoundary);
  // Floating bodies: each body particle's offset from its body's centre, kept by id.
  bodies_.init(cfg_.rigid_bodies, p_.x, p_.kind, p_.id, static_cast<double>(reference_sound_speed(cfg_)));

  set_phase_values(rho_in);
  for (const auto& ph : cfg_.phases) any_tension_ = any_tension_ || ph.sigma > 0;
  wall_states_ =
      cfg_.wall_model != WallModel::Akinci && cfg_.wall_model != WallModel::VolumeMap && fluid_count_ < n;
  stepper_ = make_model_stepper<Dim, Real, HostStepContext<Dim, Real>>(cfg_);
  // Default 0.15 h: 1.5x the pairs in the lists (3D), rebuilt every few steps at the dam break's speeds.
  skin_ = cfg_.verlet_skin * cfg_.support;
  search_h_.assign(n, Real(0));
  bare_h_.assign(n, Real(0));
  rebuild_kind_lists();
  if (cfg_.wall_model == WallModel::VolumeMap) build_wall_map();
  // Boundary particles never move: one reorder puts them in cell order for the whole run (before their
  // weights, whose sums then run in that order too).
  if (cfg_.reorder_every > 0) reorder_slots(boundary_);
  init_boundary_weights();
  set_moving_slots();
  move_walls(time_);
  set_body_slots(true);
  lists_valid_ = false;
  if (cfg_.backend != Backend::Cpu) use_backend(cfg_.backend);
}

template <int Dim, class Real>
Simulation<Dim, Real>::~Simulation() = default;
template <int Dim, class Real>
Simulation<Dim, Real>::Simulation(Simulation&&) = default;
template <int Dim, class Real>
Simulation<Dim, Real>& Simulation<Dim, Real>::operator=(Simulation&&) = default;

// Volume-map walls (boundary/bender2019.hpp): the solids are the map; wall particles would be counted
// twice. The grid of the solids other than the tank has nodes a quarter support apart (half a spacing at
// the usual h = 2 spacings: an obstacle's corner within 1% of its kernel sum, VolumeMap tests).
template <int Dim, class Real>
void Simulation<Dim, Real>::build_wall_map() {
  if (fluid_count_ < p_.size()) {
    std::ostringstream os;
    os << "boundary.model: volume-map walls take no boundary particles (the scene gives "
       << p_.size() - fluid_count_ << "): the solids' map is the walls";
    throw InputError(os.str());
  }
  if (cfg_.volume_map.empty())
    cfg_.volume_map = build_volume_map(cfg_.guard, cfg_.density_kernel, cfg_.support, cfg_.support / 4,
                                       dfsph_particle_diameter<Dim, Real>(p_.m.data(), rho0_.data(), fluid_));
}

template <int Dim, class Real>
void Simulation<Dim, Real>::set_body_slots(bool place) {
  if (domain_)
    bodies_.set_slots(p_.id, local_walls_, p_.size(), &domain_->owned());
  else
    bodies_.set_slots(p_.id, boundary_, p_.size());
  if (!bodies_.any()) return;
  if (wall_a_.size() != p_.size()) wall_a_.assign(p_.size(), V{});
  // Their rows hold their fluid neighbours (within h: the reaction) and the walls they touch.
  const Real radius = std::max(cfg_.support, static_cast<Real>(cfg_.rigid_bodies.contact_distance));
  for (const std::uint32_t b : bodies_.slots()) {
    bare_h_[b] = radius;
    search_h_[b] = radius + skin_;
  }
  if (place) bodies_.place(p_.x, p_.v, wall_a_);
  lists_valid_ = false;
}

// The bodies' fluid and contact loads (boundary/rigid_bodies.hpp) from their own rows and the force
// pass's own wall term.
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_body_loads(const ParticleView<Dim, Real>& pv) {
  with_wcsph_forces_pass(cfg_, pv, any_tension_, wall_states_,
                         [&](const auto& pass) { bodies_.compute_loads(pv, pass); });
  if (domain_) share_body_loads();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::advance_bodies(Real dt) {
  bodies_.advance(static_cast<double>(dt), cfg_.gravity);
  const auto& st = bodies_.states();
  for (std::size_t b = 0; b < st.size(); ++b) {
    bool finite = true;
    for (int a = 0; a < 3; ++a)
      finite = finite && std::isfinite(st[b].x[a]) && std::isfinite(st[b].v[a]) && std::isfinite(st[b].w[a]);
    if (!finite) {
      std::ostringstream os;
      os << "unstable at step " << steps_ << " (t = " << time_ << " s): floating body " << b
         << " has a non-finite state";
      throw SimulationError(os.str());
    }
  }
  bodies_.place(p_.x, p_.v, wall_a_);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::restore_bodies(std::vector<RigidBodyState> states, const std::string& source) {
  bodies_.set_states(std::move(states), source);
  sync_host();  // a device backend: its particles here, the bodies placed among them, all back there
  bodies_.place(p_.x, p_.v, wall_a_);
  lists_valid_ = false;
  if (device_) upload_to_device();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::set_moving_slots() {
  moving_.set_slots(p_.id, boundary_);
  if (cfg_.wall_motion.any()) wall_a_.assign(p_.size(), V{});
}

// Moving walls at time t (boundary/moving_walls.hpp); walls at rest keep v = 0.
template <int Dim, class Real>
void Simulation<Dim, Real>::move_walls(Real t) {
  moving_.move(cfg_.wall_motion, static_cast<double>(t), p_.x.data(), p_.v.data(), wall_a_.data());
}

template <int Dim, class Real>
ParticleView<Dim, Real> Simulation<Dim, Real>::view() {
  ParticleView<Dim, Real> v;
  v.n = p_.size();
  attach_particle_fields(v, p_);
  v.rho0 = rho0_.data();
  v.vol = vol_.data();
  v.prho2 = prho2_.data();
  v.normal = normal_.data();
  v.wall_v = wall_v_.data();
  v.wall_a = wall_a_.empty() ? nullptr : wall_a_.data();
  v.wall_self_rho = wall_self_rho_.data();
  v.df_kappa_v = state_.dfsph_kappa_v.data();
  v.offsets = nl_.offsets.data();
  v.candidates = nl_.indices.data();
  v.within = rows_at_h_ ? nl_.indices.data() : within_.data();
  v.within_count = within_count_.data();
  v.wall_start = walls_.start.data();
  v.wall_nbr = walls_.nbr.data();
  v.phases = phase_params_.data();
  return v;
}

// Akinci et al. 2012 weights (boundary/akinci2012.hpp) and, for dynamic walls, each wall's fixed
// wall-wall density (boundary/dynamic_crespo2007.hpp), from a search with the rows of every particle.
template <int Dim, class Real>
void Simulation<Dim, Real>::init_boundary_weights() {
  if (fluid_count_ == p_.size()) return;
  compute_neighbors(true);
  akinci2012_weights(cfg_, view());
  if (cfg_.wall_model != WallModel::Dynamic) return;
  wall_self_rho_.assign(p_.size(), Real(0));
  dynamic_wall_self_density(cfg_, view());
}

// The particles of `slots` into cell order (cell_order.hpp), with every array that persists between steps
// (the others are rebuilt before they are read).
template <int Dim, class Real>
void Simulation<Dim, Real>::reorder_slots(const IndexList& slots) {
  if (slots.size() < 2) return;
  const std::vector<std::uint32_t> from = cell_order(p_.x, p_.id, slots, cfg_.support);
  const std::size_t n = p_.size();
  auto permute = [&](auto& field) { permute_slots(field, slots, from, n); };
  p_.for_each_field([&](std::string_view, auto& field) { permute(field); });
  state_.for_each_field([&](std::string_view, auto& field) { permute(field); });
  permute(rho0_);
  permute(search_h_);
  permute(bare_h_);
  permute(vol_);
  permute(prho2_);
  lists_valid_ = false;  // x_built_ and the lists name the old slots
}

template <int Dim, class Real>
void Simulation<Dim, Real>::compute_neighbors(bool boundary_rows) {
  // Boundary rows are never read by a step (j is a neighbour of i iff |x_i - x_j| <= h_i, so fluid rows
  // do not depend on the boundary's support).
  if (boundary_rows || search_h_.size() != p_.size()) {
    search_.build(std::span<const V>(p_.x), std::span<const Real>(p_.h));
    search_.find_all(nl_);
    lists_valid_ = false;
    rows_at_h_ = true;
    return;
  }
  if (lists_valid_ && skin_ > 0) {
    // The largest squared displacement since the lists were built (order-free: a maximum).
    // Moving walls count too: a pair's distance changes by at most the sum of both displacements.
    const MaxDisplacementPass<Dim, Real> disp{view(), x_built_.data()};
    // Across ranks the halo copies count too (their owners move them).
    Real d2 = reduce_max(row_fluid(), MaxValue<Real>{}, disp).value;
    if (moving_.any()) d2 = std::max(d2, reduce_max(moving_.slots(), MaxValue<Real>{}, disp).value);
    // Across ranks the moving walls' halo copies too (a wall at rest has not moved).
    if (domain_ && (moving_.any() || bodies_.any()))
      d2 = std::max(d2, reduce_max(local_walls_, MaxValue<Real>{}, disp).value);
    if (bodies_.any()) d2 = std::max(d2, reduce_max(bodies_.slots(), MaxValue<Real>{}, disp).value);
    const Real limit = Real(0.45) * skin_;
    if (d2 <= limit * limit) {
      ++lists_kept_;
      return;
    }
    // Lists that did not last a single step: the skin only made the search and the filter longer (DFSPH's
    // CFL steps move the fastest particle 0.4 d, three times 0.45 of the default skin). Search at the
    // bare supports for a while, then try the skin again.
    if (lists_kept_ == 0) bare_searches_ = kBareSearches;
  }
  ++timings_.list_builds;
  if (skin_ > 0 && bare_searches_ > 0) {
    --bare_searches_;
    ++timings_.bare_builds;
    search_.build(std::span<const V>(p_.x), std::span<const Real>(bare_h_));
    search_.find_all(nl_);
    lists_valid_ = false;  // rows within h only: the next step searches again
    rows_at_h_ = true;
    return;
  }
  search_.build(std::span<const V>(p_.x), std::span<const Real>(search_h_));
  search_.find_all(nl_);
  rows_at_h_ = skin_ == 0;
  if (skin_ > 0) x_built_ = p_.x;
  lists_valid_ = true;
  lists_kept_ = 0;
}

// The rows of `set` cut down to the pairs within h_i (verlet_rows.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::filter_lists(const IndexList& set) {
  within_count_.resize(p_.size());
  if (rows_at_h_) {
    run_pass(set, RowLengthPass<Dim, Real>{view()});  // the rows are the candidates (view())
    return;
  }
  within_.resize(nl_.indices.size());
  run_pass(set, FilterRowsPass<Dim, Real>{view(), within_.data()});
}

// Paper eq. 7 (or the number density of Solenthaler & Pajarola 2008), then the equation of state, or
// the continuity density's pressure (models/density_pressure.hpp), for per-particle steps' work sets.
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_density_pressure(const IndexList& set) {
  timings_.density_evals += set.size();
  vol_.resize(p_.size());
  prho2_.resize(p_.size());
  fluid_density_pressure(cfg_, view(), set);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::prepare_shared_arrays() {
  vol_.resize(p_.size());
  prho2_.resize(p_.size());
  if (!wall_states_) return;
  wall_v_.resize(p_.size());
  if (boundary_.empty()) return;
  gather_wall_neighbors(view(), row_fluid(), boundary_, walls_);
}

template <int Dim, class Real>
const BalancedIndexSet& Simulation<Dim, Real>::fluid_by_pairs() {
  balance(
      fluid_, static_cast<std::size_t>(max_threads()),
      [&](std::uint32_t i) { return std::uint64_t{within_count_[i]} + kBalanceParticleWeight; },
      fluid_split_);
  return fluid_split_;
}

template <int Dim, class Real>
const DfsphStats* Simulation<Dim, Real>::solver_stats() const {
  return device_ ? device_->solver_stats() : stepper_->solver_stats();
}

template <int Dim, class Real>
const DfsphStats& Simulation<Dim, Real>::dfsph_stats() const {
  static const DfsphStats none{};
  const DfsphStats* s = solver_stats();
  return s ? *s : none;
}

template <int Dim, class Real>
std::string Simulation<Dim, Real>::solver_progress() const {
  return stepper_->progress(dfsph_stats(), clock_.last_dt);
}

template <int Dim, class Real>
std::vector<std::string> Simulation<Dim, Real>::solver_summary() const {
  return stepper_->summary(dfsph_stats(), timings_.neighbors);
}

// The box and the planes (integration/collisions.hpp), then the solid guard (boundary/solid_guard.hpp)
// with the moving solids where the step ends: the prescribed motions at the step's end time, the bodies
// moved on by their velocities (boundary/solid_guard_frames.hpp). `dt`: the step's drift (0: fast particles
// are not followed).
template <int Dim, class Real>
void Simulation<Dim, Real>::apply_walls(Real dt) {
  if (cfg_.box.enabled || !cfg_.planes.empty()) run_pass(fluid_, box_plane_collisions(cfg_, view()));
  if (!cfg_.guard.any()) return;
  std::vector<GuardFrame> frames;
  if (cfg_.guard.moving())
    frames = guard_frames(cfg_, static_cast<double>(time_ + dt), static_cast<double>(dt), bodies_.states());
  const auto pass = solid_guard(cfg_.guard, view(), frames.data(),
                                static_cast<std::int32_t>(cfg_.wall_motion.motions.size()), dt);
  const auto put_back = static_cast<std::uint64_t>(reduce_sum(fluid_, pass));
  wall_corrections_ += domain_ ? domain_->sum(put_back) : put_back;
}

// After each step: the first particle (lowest index) with a non-finite quantity or outside the domain
// stops the run with a diagnosis.
template <int Dim, class Real>
void Simulation<Dim, Real>::check_state() {
  const auto check = stability_check(cfg_, view());
  const std::int64_t first = first_where(fluid_, check);
  if (!domain_) {
    if (first >= 0) report_unstable(first);
    return;
  }
  // Across ranks: the lowest failing id over every rank (the single-process run's first, in id order),
  // told by the rank that owns it.
  const std::int64_t id = first >= 0 ? std::int64_t{p_.id[static_cast<std::size_t>(first)]} : -1;
  const std::int64_t lowest = domain_->lowest(id);
  if (lowest < 0) return;
  throw SimulationError(domain_->message(id == lowest ? unstable_message(first) : std::string()));
}

// The SimulationError of check_state for fluid particle `first` (the lowest failing index).
template <int Dim, class Real>
void Simulation<Dim, Real>::report_unstable(std::int64_t first) const {
  sync_host();
  throw SimulationError(unstable_message(first));
}

template <int Dim, class Real>
std::string Simulation<Dim, Real>::unstable_message(std::int64_t first) const {
  std::ostringstream os;
  os.precision(9);
  os << "simulation unstable at step " << steps_ + 1 << " (t = " << time_
     << " s): " << describe_unstable(first);
  return os.str();
}

// An implicit solve that diverged (the SimulationError being handled, models/dfsph.hpp's
// implicit_check_solve): rethrown with the first fluid particle (lowest index) that the stability check
// finds bad, where there is one (a velocity the solve's kicks made non-finite). Called from a catch block.
template <int Dim, class Real>
void Simulation<Dim, Real>::report_diverged_solve(const SimulationError& e) {
  sync_host();
  const std::int64_t first = first_where(fluid_, stability_check(cfg_, view()));
  if (first < 0) throw;
  throw SimulationError(std::string(e.what()) + "; the first bad particle: " + describe_unstable(first));
}

// What is wrong with fluid particle `first`: "particle i (id k): velocity = (...)" and the like.
template <int Dim, class Real>
std::string Simulation<Dim, Real>::describe_unstable(std::int64_t first) const {
  const auto check = stability_check(cfg_, ParticleView<Dim, Real>{});
  const V lo = check.lo, hi = check.hi;
  const Real margin = check.margin;
  const auto i = static_cast<std::size_t>(first);
  std::ostringstream os;
  os.precision(9);
  // Across ranks the slot of the single-process arrays is the id (they are in id order).
  os << "particle " << (domain_ ? std::size_t{p_.id[i]} : i) << " (id " << p_.id[i] << "): ";
  auto vec = [&](const char* name, const V& v) {
    os << name << " = (";
    for (int a = 0; a < Dim; ++a) os << (a ? ", " : "") << v[a];
    os << ")";
  };
  if (!all_finite(p_.x[i]))
    vec("position", p_.x[i]);
  else if (!all_finite(p_.v[i]))
    vec("velocity", p_.v[i]);
  else if (!all_finite(p_.f[i]))
    vec("force", p_.f[i]);
  else if (!std::isfinite(norm2(p_.v[i]))) {
    vec("velocity", p_.v[i]);
    os << ": its square overflows (the Courant step would be 0)";
  } else if (!std::isfinite(norm2(p_.f[i]) / (p_.m[i] * p_.m[i]))) {
    vec("force", p_.f[i]);
    os << " on mass " << p_.m[i] << ": the acceleration's square overflows (the Courant step would be 0)";
  } else if (!std::isfinite(p_.rho[i]))
    os << "density = " << p_.rho[i];
  else if (!(p_.rho[i] > 0)) {
    os << "density = " << p_.rho[i] << " is not positive";
    if (cfg_.density_evolution == DensityEvolution::Continuity && cfg_.model == Model::Wcsph)
      os << " (the continuity density of a particle compressed and then torn apart: a smaller step, "
            "more wall layers or summation density)";
  } else if (!std::isfinite(p_.p[i]))
    os << "pressure = " << p_.p[i];
  else {
    vec("position", p_.x[i]);
    os << " left the domain";
    vec(" [lo", lo);
    vec(", hi", hi);
    os << "] (margin " << margin << " m)";
    if (cfg_.domain_default)
      os << "; the scene sets no /domain: the default is its starting particles' bounding box grown by its "
            "longest side on every side (set /domain for another)";
  }
  return os.str();
}

// Per-particle power-of-two steps (timestep/per_particle_levels.hpp): the clock T is the smallest
// particle time; the due particles' forces are evaluated with every position extrapolated to T, then
// each due particle picks its level and is kicked and drifted.
template <int Dim, class Real>
void Simulation<Dim, Real>::step_per_particle() {
  const int L = cfg_.time.max_level;
  const Real unit = cfg_.time.dt_max / static_cast<Real>(std::int64_t{1} << L);
  std::int64_t T = earliest_tick(view(), fluid_);
  if (T == std::numeric_limits<std::int64_t>::max()) T = 0;

  Stopwatch sw;
  // Reorder on the clock, at multiples of reorder_every * dt_max: particles' steps are aligned to
  // multiples of themselves, so there every particle is due (synchronised), and the schedule is a
  // function of the ticks (checkpointed) alone.
  const std::int64_t period = static_cast<std::int64_t>(cfg_.reorder_every) << L;
  if (period > 0 && T % period == 0) {
    reorder_slots(fluid_);
    ++timings_.reorders;
    timings_.reorder += sw.ms();
    sw.reset();
  }
  due_list_.clear();
  for (const std::uint32_t i : fluid_)
    if (p_.tick[i] == T) due_list_.push_back(i);
  xs_ = p_.x;
  run_pass(fluid_, ExtrapolatePass<Dim, Real>{view(), xs_.data(), T, unit});
  std::swap(p_.x, xs_);  // the force passes see positions at time T
  compute_neighbors();
  timings_.neighbors += sw.ms();
  sw.reset();
  // CSF and Akinci read the normals of neighbours, which read the densities of theirs.
  const bool normals = PaperTension::of(cfg_, any_tension_).needs_normals();
  build_work_sets(view(), fluid_, due_list_, normals, full_passes_, mark_, normal_set_, rho_set_);
  filter_lists(rho_set_);  // every pass below reads rows of rho_set_ only (it holds the other sets)
  compute_density_pressure(rho_set_);
  const auto tension = PaperTension::of(cfg_, any_tension_);
  timings_.force_evals += due_list_.size();
  if (tension.needs_normals()) timings_.normal_evals += normal_set_.size();
  paper_normals_and_forces(cfg_, view(), due_list_, normal_set_, normal_, tension, wall_states_,
                           [](const auto&) {});
  std::swap(p_.x, xs_);
  timings_.forces += sw.ms();

  sw.reset();
  per_particle_levels(cfg_, view(), due_list_, T, clock_.started);
  clock_.started = true;
  apply_walls(0);
  check_state();
  std::int64_t next = earliest_tick(view(), fluid_);
  if (next == std::numeric_limits<std::int64_t>::max()) next = T + (std::int64_t{1} << L);
  clock_.last_dt = static_cast<Real>(next - T) * unit;
  time_ = static_cast<Real>(next) * unit;
  ++steps_;
  timings_.integration += sw.ms();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::step() {
  if (device_) {
    step_device();
    return;
  }
  if (cfg_.time.mode == TimeStepping::PerParticle) {
    step_per_particle();
    return;
  }
  Stopwatch sw;
  if (domain_) update_domain();
  // On the step count alone (checkpointed), never on the list rebuilds: see the header.
  if (cfg_.reorder_every > 0 && steps_ % cfg_.reorder_every == 0) {
    reorder_slots(fluid_);
    ++timings_.reorders;
    timings_.reorder += sw.ms();
    sw.reset();
  }
  inflow_.mark(cfg_.inflow, double(time_), fluid_, p_.x);
  compute_neighbors();
  timings_.neighbors += sw.ms();

  sw.reset();
  filter_lists(row_fluid());
  prepare_shared_arrays();
  HostStepContext<Dim, Real> ctx(*this, sw);
  Real dt = 0;
  try {
    dt = stepper_->advance(ctx);  // to the drift; the stepper ends the force phase's timing
  } catch (const SimulationError& e) {
    report_diverged_solve(e);
  }
  inflow_.hold(fluid_, p_.x.data(), p_.v.data(), dt);
  apply_walls(dt);
  check_state();
  time_ += dt;
  clock_.last_dt = dt;
  ++steps_;
  move_walls(time_);  // the walls where the next step's forces see them (and outputs, checkpoints)
  if (bodies_.any()) advance_bodies(dt);
  inflow_end_step(dt, true);
  timings_.integration += sw.ms();
}

// The kind lists, rest densities and search radii from the particles (after a restore or a count change).
template <int Dim, class Real>
void Simulation<Dim, Real>::rebuild_kind_lists() {
  fluid_.clear();
  boundary_.clear();
  local_fluid_.clear();
  local_walls_.clear();
  for (std::size_t i = 0; i < p_.size(); ++i) {
    rho0_[i] = cfg_.phases[static_cast<std::size_t>(p_.phase[i])].rest_density;
    const bool fluid = p_.kind[i] == kFluid;
    if (domain_) (fluid ? local_fluid_ : local_walls_).push_back(static_cast<std::uint32_t>(i));
    if (!domain_ || domain_->owned()[i])
      (fluid ? fluid_ : boundary_).push_back(static_cast<std::uint32_t>(i));
    bare_h_[i] = fluid ? p_.h[i] : Real(0);
    search_h_[i] = fluid ? p_.h[i] + skin_ : Real(0);
  }
  fluid_count_ = fluid_.size();
  lists_valid_ = false;
}

// After the step: the sinks' particles are removed, then the layers due are appended (inflow_outflow.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::inflow_end_step(Real dt, bool maybe_in_sink) {
  if (!cfg_.inflow.any()) return;
  std::vector<V> xs;
  std::vector<std::int32_t> emitter_of;
  inflow_.due_layers(cfg_.inflow, dt, xs, emitter_of);
  if (xs.empty() && !maybe_in_sink) return;
  // A device backend: the count changes here, on the host, from the device's particles (put back below).
  sync_host();
  const std::vector<std::uint8_t> keep = inflow_.sink_keep(cfg_.inflow, fluid_, p_.x);
  if (keep.empty() && xs.empty()) return;
  inflow_.check_ids(xs.size(), time_);
  change_count(keep, xs.size());
  inflow_.fill_emitted(cfg_, p_, p_.size() - xs.size(), xs, emitter_of);
  rebuild_kind_lists();
  set_moving_slots();
  move_walls(time_);
  set_body_slots(true);  // their particles' slots moved; placed again from the same states: the same bits
  if (device_) upload_to_device();  // everything the device holds, at the new count
}

// Stable compaction by `keep`, then `added` zero entries, in every array of one entry per particle (those
// of another size are scratch not in use, as in reorder_slots).
template <int Dim, class Real>
void Simulation<Dim, Real>::change_count(const std::vector<std::uint8_t>& keep, std::size_t added) {
  const std::size_t n = p_.size();
  auto edit = [&](auto& field) {
    if (field.size() != n) return;
    std::size_t w = n;
    if (!keep.empty()) {
      w = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (keep[i]) field[w++] = field[i];
    }
    field.resize(w);
    field.resize(w + added);
  };
  p_.for_each_field([&](std::string_view, auto& field) { edit(field); });
  state_.for_each_field([&](std::string_view, auto& field) { edit(field); });
  edit(rho0_);
  edit(search_h_);
  edit(bare_h_);
  edit(vol_);
  edit(prho2_);
  edit(normal_);
  edit(wall_v_);
  edit(wall_self_rho_);
  edit(wall_a_);
  edit(within_count_);
  lists_valid_ = false;
}

template <int Dim, class Real>
void Simulation<Dim, Real>::run_until(Real t_end) {
  while (time_ < t_end) step();
}

template <int Dim, class Real>
auto Simulation<Dim, Real>::momentum() const -> V {
  sync_host();
  V s{};
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.v[i] * p_.m[i];
  return s;
}

template <int Dim, class Real>
Real Simulation<Dim, Real>::kinetic_energy() const {
  sync_host();
  Real s = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.m[i] * norm2(p_.v[i]) / 2;
  return s;
}

template <int Dim, class Real>
Real Simulation<Dim, Real>::total_mass() const {
  sync_host();
  Real s = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.kind[i] == kFluid) s += p_.m[i];
  return s;
}

// A checkpoint's count and ids against this simulation (InputError prefixed with `source`). Returns the
// next id its emitters continue from.
template <int Dim, class Real>
std::uint64_t Simulation<Dim, Real>::check_restored_ids(const Particles<Dim, Real>& particles,
                                                        const IntegratorState<Real>& state,
                                                        const std::string& source) const {
  const std::size_t n = particles.size();
  const bool inflow = cfg_.inflow.any();
  if (n != p_.size() && !inflow) {
    throw InputError(source + ": holds " + std::to_string(n) + " particles, the scene has " +
                     std::to_string(p_.size()));
  }
  if (particles.id.size() != n) {
    throw InputError(source + ": holds " + std::to_string(particles.id.size()) + " particle ids for " +
                     std::to_string(n) + " particles");
  }
  // With emitters and sinks the ids are unique and below the next id (emitted particles take new ids,
  // removed ones leave gaps); otherwise a permutation of 0..n-1.
  std::uint64_t next_id = state.next_id;
  if (inflow) {
    std::vector<std::uint32_t> ids = particles.id;
    std::sort(ids.begin(), ids.end());
    for (std::size_t i = 1; i < ids.size(); ++i)
      if (ids[i] == ids[i - 1])
        throw InputError(source + ": two particles have id " + std::to_string(ids[i]));
    const std::uint64_t above = ids.empty() ? 0 : std::uint64_t{ids.back()} + 1;
    if (next_id == 0) next_id = above;
    if (next_id < above)
      throw InputError(source + ": particle id " + std::to_string(ids.back()) + " is not below the next id " +
                       std::to_string(next_id));
    if (!state.emitter_advance.empty() && state.emitter_advance.size() != inflow_.emitters())
      throw InputError(source + ": holds the state of " + std::to_string(state.emitter_advance.size()) +
                       " emitters, the scene has " + std::to_string(inflow_.emitters()));
    for (const double a : state.emitter_advance)
      if (!(a >= 0 && a < 2 * cfg_.inflow.spacing))
        throw InputError(source + ": emitter advance " + std::to_string(a) + " is outside [0, 2 spacings)");
  } else if (const auto err = id_permutation_error(particles.id); !err.empty()) {
    throw InputError(source + ": " + err);
  }
  return next_id;
}

// Values no run holds in a checkpoint's particles, solver state (completed with 0 where empty) and clock
// (InputError prefixed with `source`).
template <int Dim, class Real>
void Simulation<Dim, Real>::check_restored_values(const Particles<Dim, Real>& particles,
                                                  SolverState<Dim, Real>& solver,
                                                  const IntegratorState<Real>& state,
                                                  const std::string& source) const {
  const std::size_t n = particles.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.phase[i] < 0 || static_cast<std::size_t>(particles.phase[i]) >= cfg_.phases.size() ||
        particles.kind[i] > kBoundary) {
      throw InputError(source + ": particle " + std::to_string(i) + " has phase " +
                       std::to_string(particles.phase[i]) + " / kind " +
                       std::to_string(int(particles.kind[i])) + ", not in this scene's tables");
    }
  }
  // Values no run holds (a checkpoint from another writer, or edited with its checksum fixed): refused
  // here, where the step would meet them as an internal error or undefined behaviour (non-finite
  // coordinates in the neighbour search, a shift by a level outside 0..max_level, ticks that overflow).
  particles.for_each_field([&](std::string_view name, const auto& field) {
    using T = typename std::remove_cvref_t<decltype(field)>::value_type;
    for (std::size_t i = 0; i < field.size(); ++i) {
      bool finite = true;
      if constexpr (std::is_same_v<T, Real>) {
        finite = std::isfinite(field[i]);
      } else if constexpr (std::is_same_v<T, V>) {
        for (int a = 0; a < Dim; ++a) finite = finite && std::isfinite(field[i][a]);
      }
      if (!finite)
        throw InputError(source + ": particle " + std::to_string(i) + " has a non-finite " +
                         std::string(name));
    }
  });
  // The solver state: one finite entry per particle, or none (0).
  solver.for_each_field([&](std::string_view name, auto& field) {
    using T = typename std::remove_cvref_t<decltype(field)>::value_type;
    if (field.empty()) field.assign(n, T{});
    if (field.size() != n)
      throw InputError(source + ": holds " + std::to_string(field.size()) + " entries of the solver state '" +
                       std::string(name) + "' for " + std::to_string(n) + " particles");
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(field[i]))
        throw InputError(source + ": particle " + std::to_string(i) + " has a non-finite " +
                         std::string(name));
  });
  if (!(std::isfinite(state.time) && state.time >= 0 && std::isfinite(state.last_dt) && state.last_dt >= 0))
    throw InputError(source + ": simulated time " + std::to_string(state.time) + " / last step " +
                     std::to_string(state.last_dt) + " is not a finite number >= 0");
  // Every particle's support is the scene's (set at construction, never changed), and per-particle steps
  // keep every fluid particle's tick within 2^max_level of the earliest (a due particle moves at most
  // dt_max ahead), so no step extrapolates a position further than dt_max.
  const std::int64_t max_tick = std::int64_t{1} << 62, spread = std::int64_t{1} << cfg_.time.max_level;
  std::int64_t lo_tick = max_tick, hi_tick = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.h[i] != cfg_.support)
      throw InputError(source + ": particle " + std::to_string(i) + " has support " +
                       std::to_string(particles.h[i]) + ", the scene's is " + std::to_string(cfg_.support));
    if (particles.level[i] < 0 || particles.level[i] > cfg_.time.max_level || particles.tick[i] < 0 ||
        particles.tick[i] > max_tick)
      throw InputError(source + ": particle " + std::to_string(i) + " has time-step level " +
                       std::to_string(particles.level[i]) + " / tick " + std::to_string(particles.tick[i]) +
                       ", outside 0.." + std::to_string(cfg_.time.max_level) + " / 0..2^62");
    // The continuity density is state: a fluid density of 0 or less would divide by zero in the next step.
    if (particles.kind[i] == kFluid && cfg_.density_evolution == DensityEvolution::Continuity &&
        !(particles.rho[i] > 0))
      throw InputError(source + ": fluid particle " + std::to_string(i) + " has density " +
                       std::to_string(particles.rho[i]) + " (the continuity density needs one > 0)");
    if (particles.kind[i] == kFluid) {
      lo_tick = std::min(lo_tick, particles.tick[i]);
      hi_tick = std::max(hi_tick, particles.tick[i]);
    }
  }
  if (hi_tick > lo_tick && hi_tick - lo_tick > spread)
    throw InputError(source + ": fluid particles' ticks span " + std::to_string(lo_tick) + ".." +
                     std::to_string(hi_tick) + ", more than 2^" + std::to_string(cfg_.time.max_level) +
                     " (one largest step)");
}

template <int Dim, class Real>
void Simulation<Dim, Real>::restore(Particles<Dim, Real> particles, const IntegratorState<Real>& state,
                                    const std::string& source, SolverState<Dim, Real> solver) {
  const std::size_t n = particles.size();
  const bool inflow = cfg_.inflow.any();
  const std::uint64_t next_id = check_restored_ids(particles, state, source);
  check_restored_values(particles, solver, state, source);
  p_ = std::move(particles);
  rho0_.resize(n);
  search_h_.resize(n);
  bare_h_.resize(n);
  rebuild_kind_lists();
  state_ = std::move(solver);
  if (inflow) inflow_.restore(next_id, state.emitter_advance, cfg_.inflow.spacing);
  // Dynamic walls: their fixed density share, from the restored walls (kept weights, no reorder). Its
  // neighbour search is the first to see the positions: one beyond what a search can index (1e86 m) is
  // the file's fault, named as such (the Simulation is then not usable; the caller stops).
  set_moving_slots();
  set_body_slots(false);  // their particles are the checkpoint's; restore_bodies sets their states
  if (cfg_.wall_model == WallModel::Dynamic) {
    // Moving walls: the fixed share is that of the initial positions, as at construction.
    moving_.to_initial(p_.x.data());
    try {
      init_boundary_weights();
    } catch (const CapacityError& e) {
      throw InputError(source + ": " + e.what());
    }
  }
  time_ = state.time;
  clock_.last_dt = state.last_dt;
  steps_ = state.steps;
  clock_.started = state.leapfrog_started;
  move_walls(time_);
  if (device_) {
    upload_to_device();
    host_stale_ = false;
  }
}

template <int Dim, class Real>
void Simulation<Dim, Real>::use_backend(Backend b) {
  if (b == backend_) return;
  if (b == Backend::Cpu) {
    sync_host();
    move_walls(time_);  // their accelerations (wall_a_, not a particle field) at the device's clock
    if (DfsphStats* s = stepper_->solver_stats()) *s = *device_->solver_stats();
    device_.reset();
    backend_ = b;
    lists_valid_ = false;
    return;
  }
  require_backend(b, "solver.backend");
  if (const std::string why = device_step_unsupported(cfg_); !why.empty())
    throw InputError("solver.backend " + std::string(backend_name(b)) + ": " + why);
  sync_host();
  device_ = b == Backend::Cuda ? make_cuda_stepper(cfg_) : make_host_device_stepper(cfg_);
  if (const DfsphStats* s = stepper_->solver_stats())
    *device_->solver_stats() = *s;  // the run's counts go on
  upload_to_device();
  backend_ = b;
}

// The particles and, for dynamic walls, their fixed wall-wall densities (init_boundary_weights).
template <int Dim, class Real>
void Simulation<Dim, Real>::upload_to_device() {
  device_->upload(p_);
  if (cfg_.wall_model == WallModel::Dynamic && !boundary_.empty())
    device_->upload_wall_self_density(wall_self_rho_);
  if (moving_.any() || !wall_a_.empty())
    device_->upload_wall_motion(moving_.slots(), moving_.initial_positions(), moving_.motions(), wall_a_);
  if (bodies_.any()) device_->upload_bodies(bodies_);
  if (implicit_pressure(cfg_.model)) device_->upload_solver_state(state_);
}

// One step of the device backend (solver/device/device_stepper.hpp): the sequence of step() for WCSPH or
// the paper's model with global steps, on the device's copy of the particles.
template <int Dim, class Real>
void Simulation<Dim, Real>::step_device() {
  if (cfg_.reorder_every > 0 && steps_ % cfg_.reorder_every == 0) {
    // step()'s reorder, on the host's copy: every field comes back, is permuted by the CPU's code and goes
    // again (the round trip of an emitter's count change), so the device keeps the CPU's order and bits.
    Stopwatch sw;
    sync_host();
    reorder_slots(fluid_);
    upload_to_device();
    ++timings_.reorders;
    timings_.reorder += sw.ms();
  }
  DeviceStepInput<Real> in{time_, clock_, steps_ + 1};
  if (inflow_.activity(cfg_.inflow, double(time_))) in.emitters_active = inflow_.active_flags();
  if (bodies_.any()) in.bodies = &bodies_.states();
  DeviceStepResult<Real> r{};
  try {
    r = device_->step(in);
  } catch (const SimulationError& e) {
    host_stale_ = true;  // the device's particles, as the diverged solve left them
    report_diverged_solve(e);
  }
  clock_.started = r.leapfrog_started;
  wall_corrections_ += static_cast<std::uint64_t>(r.guard_corrections);
  host_stale_ = true;
  timings_.neighbors += r.neighbors_ms;
  timings_.forces += r.forces_ms;
  timings_.integration += r.integration_ms;
  ++timings_.list_builds;
  timings_.density_evals += fluid_count_;
  timings_.force_evals += fluid_count_;
  if (r.first_bad >= 0) report_unstable(r.first_bad);  // copies the particles back to describe it
  time_ += r.dt;
  clock_.last_dt = r.dt;
  ++steps_;
  if (bodies_.any()) {
    // The loads from the device's per-particle forces, summed here in the CPU's order; the rigid step
    // here (also placing the host's copy of their particles and accelerations), the placement there.
    device_->download_body_forces(body_f_, body_x_);
    bodies_.sum_loads(body_f_, body_x_);
    advance_bodies(r.dt);
    device_->place_bodies(bodies_.states());
  }
  inflow_end_step(r.dt, r.first_in_sink >= 0);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::sync_host() const {
  if (!host_stale_) return;
  device_->download(p_);
  if (implicit_pressure(cfg_.model)) device_->download_solver_state(state_);
  host_stale_ = false;
}

template class Simulation<2, float>;
template class Simulation<2, double>;
template class Simulation<3, float>;
template class Simulation<3, double>;

}  // namespace cellsph
