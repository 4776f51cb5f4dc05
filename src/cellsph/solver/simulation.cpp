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
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/boundary/adami2012.hpp"
#include "cellsph/solver/boundary/akinci2012.hpp"
#include "cellsph/solver/boundary/dynamic_crespo2007.hpp"
#include "cellsph/solver/boundary/wall_neighbors.hpp"
#include "cellsph/solver/integration/collisions.hpp"
#include "cellsph/solver/models/continuity_density.hpp"
#include "cellsph/solver/models/paper_multiphase.hpp"
#include "cellsph/solver/models/summation_density.hpp"
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

// Z-order (Morton) key of a cell: the bits of the cell coordinates interleaved, so that cells close in
// space are mostly close in the key and each block of 2^Dim, 4^Dim, ... cells is contiguous.
template <int Dim>
std::uint64_t morton_key(const std::uint64_t (&c)[Dim]) {
  constexpr int bits = 64 / Dim;
  std::uint64_t key = 0;
  for (int b = 0; b < bits; ++b)
    for (int a = 0; a < Dim; ++a) key |= ((c[a] >> b) & 1u) << (b * Dim + a);
  return key;
}

// The step's search: the wall particles search with support 0 (search_h_) and no pass reads their rows,
// so Cell Indexing leaves them empty instead of searching them.
SearchOptions step_search(SearchOptions o) {
  o.zero_support_rows = false;
  return o;
}

}  // namespace

template <int Dim, class Real>
Simulation<Dim, Real>::Simulation(Config config, Particles<Dim, Real> particles)
    : cfg_(std::move(config)), p_(std::move(particles)), search_(step_search(cfg_.search)) {
  cfg_.validate();
  for (const auto& ph : cfg_.phases) phase_params_.push_back({ph.rest_density, ph.viscosity, ph.sigma});
  const std::size_t n = p_.x.size();
  // Inputs that may be left empty get their defaults; any other size mismatch is an error.
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
  rho0_.assign(n, Real(0));
  state_.assign_zero(n);
  // Emitters: frames from the config; the first layer is due at the start (advance = one spacing), so
  // the emitted lattice continues a fluid block that begins at the emitter plane.
  next_id_ = n;
  for (std::size_t k = 0; k < cfg_.inflow.emitters.size(); ++k) {
    const Emitter& e = cfg_.inflow.emitters[k];
    const auto& phase = cfg_.phases[static_cast<std::size_t>(e.phase)];
    if (!(phase.mass > 0 && std::isfinite(phase.mass)))
      throw InputError("emitters[" + std::to_string(k) + "].phase: phase '" + phase.name + "' has mass " +
                       std::to_string(phase.mass) + " (phases[" + std::to_string(e.phase) +
                       "].mass): emitted particles need one > 0");
    frames_.push_back(emitter_frame<Dim, Real>(e, cfg_.inflow.spacing, double(cfg_.support)));
    emitter_planes_.push_back(frames_.back());
    advance_.push_back(cfg_.inflow.spacing);
  }
  // Moving walls: each particle's motion and initial position, kept by id (the input order's index is
  // lost when the boundary is reordered below).
  if (cfg_.wall_motion.any()) {
    const auto& of = cfg_.wall_motion.of_particle;
    if (of.size() != n)
      throw InputError("particles: the wall motions name " + std::to_string(of.size()) +
                       " particles, there are " + std::to_string(n));
    x0_of_id_.assign(n, V{});
    motion_of_id_.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      if (of[i] >= 0 && p_.kind[i] != kBoundary)
        throw InputError("particles: fluid particle " + std::to_string(i) + " is given a wall motion");
      x0_of_id_[p_.id[i]] = p_.x[i];
      motion_of_id_[p_.id[i]] = of[i];
    }
  }
  // Floating bodies: each body particle's offset from its body's centre, kept by id.
  bodies_.init(cfg_.rigid_bodies, p_.x, p_.kind, p_.id, static_cast<double>(reference_sound_speed(cfg_)));

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
  for (const auto& ph : cfg_.phases) any_tension_ = any_tension_ || ph.sigma > 0;
  wall_states_ = cfg_.wall_model != WallModel::Akinci && fluid_count_ < n;
  f_pressure_.assign(n, V{});
  fluid_.clear();
  fluid_.reserve(fluid_count_);
  boundary_.clear();
  // Default 0.15 h: 1.5x the pairs in the lists (3D), rebuilt every few steps at the dam break's speeds.
  skin_ = cfg_.verlet_skin * cfg_.support;
  search_h_.assign(n, Real(0));
  bare_h_.assign(n, Real(0));
  for (std::size_t i = 0; i < n; ++i) {
    if (p_.kind[i] != kFluid) {
      boundary_.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    fluid_.push_back(static_cast<std::uint32_t>(i));
    bare_h_[i] = p_.h[i];
    search_h_[i] = p_.h[i] + skin_;
  }
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
void Simulation<Dim, Real>::set_body_slots(bool place) {
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
void Simulation<Dim, Real>::compute_body_loads() {
  const ParticleView<Dim, Real> pv = view();
  with_wcsph_forces_pass(cfg_, pv, any_tension_, wall_states_,
                         [&](const auto& pass) { bodies_.compute_loads(pv, pass); });
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
  moving_.clear();
  moving_x0_.clear();
  moving_motion_.clear();
  if (!cfg_.wall_motion.any()) return;
  for (const std::uint32_t b : boundary_) {
    const std::int32_t m = motion_of_id_[p_.id[b]];
    if (m < 0) continue;
    moving_.push_back(b);
    moving_x0_.push_back(x0_of_id_[p_.id[b]]);
    moving_motion_.push_back(m);
  }
  wall_a_.assign(p_.size(), V{});
}

// Moving walls at time t (boundary/wall_motion.hpp): positions, velocities and accelerations from the
// initial positions; walls at rest keep v = 0.
template <int Dim, class Real>
void Simulation<Dim, Real>::move_walls(Real t) {
  if (moving_.empty()) return;
  run_pass(moving_.size(), MovingWallPass<Dim, Real>{p_.x.data(), p_.v.data(), wall_a_.data(), moving_.data(),
                                                     moving_x0_.data(), moving_motion_.data(),
                                                     cfg_.wall_motion.motions.data(),
                                                     cfg_.wall_motion.rows.data(), static_cast<double>(t)});
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
  v.f_pressure = f_pressure_.data();
  v.wall_v = wall_v_.data();
  v.wall_a = wall_a_.empty() ? nullptr : wall_a_.data();
  v.wall_self_rho = wall_self_rho_.data();
  v.drho = drho_.data();
  v.df_alpha = df_alpha_.data();
  v.df_kappa = df_kappa_.data();
  v.df_kappa_v = state_.dfsph_kappa_v.data();
  v.df_grad = df_grad_.data();
  v.df_gsum = df_gsum_.data();
  v.df_gwall = df_gwall_.data();
  v.df_mv = df_mv_.data();
  v.df_mk = df_mk_.data();
  v.cg_v0 = cg_v0_.data();
  v.cg_s = cg_s_.data();
  v.cg_p = cg_p_.data();
  v.cg_ap = cg_ap_.data();
  v.cg_active = cg_active_.data();
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

// Cells of size h counted from the lowest corner of these particles, keyed in Z-order; equal keys by id.
// The order is a function of positions and ids alone (a total order, so any sort gives it), which
// keeps results independent of the neighbour method, the skin and the thread count. Particles move
// only among `slots`, so every slot keeps its kind.
template <int Dim, class Real>
void Simulation<Dim, Real>::reorder_slots(const IndexList& slots) {
  const std::size_t m = slots.size();
  if (m < 2) return;
  V lo = p_.x[slots[0]];
  for (const std::uint32_t i : slots)
    for (int a = 0; a < Dim; ++a) lo[a] = std::min(lo[a], p_.x[i][a]);
  const Real inv = Real(1) / cfg_.support;
  constexpr std::uint64_t cmax = (std::uint64_t{1} << (64 / Dim)) - 1;
  struct Item {
    std::uint64_t key;
    std::uint32_t id, slot;
  };
  std::vector<Item> items(m);
  parallel_for(m, [&](std::size_t k) {
    const std::uint32_t i = slots[k];
    std::uint64_t c[Dim];
    for (int a = 0; a < Dim; ++a) {
      // Finite positions (check_state) at or above lo; far cells are clamped (only the order suffers).
      const Real q = std::min(std::floor((p_.x[i][a] - lo[a]) * inv), static_cast<Real>(cmax));
      c[a] = std::min(static_cast<std::uint64_t>(q), cmax);
    }
    items[k] = {morton_key<Dim>(c), p_.id[i], i};
  });
  std::sort(items.begin(), items.end(),
            [](const Item& a, const Item& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
  // Slot slots[k] receives the particle from slot items[k].slot.
  auto permute = [&](auto& field) {
    if (field.size() != p_.size()) return;  // a scratch array not in use
    using T = typename std::remove_reference_t<decltype(field)>::value_type;
    std::vector<T> tmp(m);
    parallel_for(m, [&](std::size_t k) { tmp[k] = field[items[k].slot]; });
    parallel_for(m, [&](std::size_t k) { field[slots[k]] = tmp[k]; });
  };
  p_.for_each_field([&](std::string_view, auto& field) { permute(field); });
  // Every member array that persists between steps (the others are rebuilt before they are read).
  permute(rho0_);
  permute(search_h_);
  permute(bare_h_);
  permute(vol_);
  permute(prho2_);
  permute(f_pressure_);
  permute(normal_);
  state_.for_each_field([&](std::string_view, auto& field) { permute(field); });
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
    Real d2 = reduce_max(fluid_, MaxValue<Real>{}, disp).value;
    if (!moving_.empty()) d2 = std::max(d2, reduce_max(moving_, MaxValue<Real>{}, disp).value);
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

// Paper eq. 7 (or the number density of Solenthaler & Pajarola 2008), then the equation of state
// (models/summation_density.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_density_pressure(const IndexList& set) {
  timings_.density_evals += set.size();
  vol_.resize(p_.size());
  prho2_.resize(p_.size());
  if (cfg_.density_evolution == DensityEvolution::Continuity)
    continuity_state(cfg_, view(), set);  // models/continuity_density.hpp
  else
    summation_density(cfg_, view(), set);
}

// Adami or dynamic walls: each wall particle's pressure, density (and no-slip velocity) from its fluid
// neighbours, after the density pass (boundary/adami2012.hpp, boundary/dynamic_crespo2007.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_wall_states() {
  if (boundary_.empty()) return;
  wall_v_.resize(p_.size());
  gather_wall_neighbors(view(), fluid_, boundary_, walls_);
  if (cfg_.wall_model == WallModel::Dynamic)
    dynamic_wall_states(cfg_, view(), boundary_);
  else
    adami2012_wall_states(cfg_, view(), boundary_);
}

// CSF (or Akinci 2013) colour normals of `set` (models/paper_multiphase.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_normals(const IndexList& set) {
  timings_.normal_evals += set.size();
  normal_.assign(p_.size(), V{});
  paper_normals(cfg_, view(), set);
}

// Algorithm 1, lines 2-15 (models/paper_multiphase.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_forces_paper(const IndexList& set, const IndexList& normal_set) {
  timings_.force_evals += set.size();
  const auto tension = PaperTension::of(cfg_, any_tension_);
  if (tension.needs_normals()) compute_normals(normal_set);
  paper_forces(cfg_, view(), set, tension, wall_states_);
}

// The write-up's forces (models/wcsph.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::compute_forces_wcsph() {
  timings_.force_evals += fluid_.size();
  wcsph_forces(cfg_, view(), fluid_, any_tension_, wall_states_);
}

// Fixed, or the global Courant step (timestep/global_courant.hpp).
template <int Dim, class Real>
Real Simulation<Dim, Real>::choose_dt() {
  return global_courant_dt(cfg_, view(), fluid_);
}

// Leap-frog (eq. 11, models/paper_multiphase.hpp). On the first step v(t0) becomes v(t0 + dt/2); with a
// changing step the kick uses the mean of the old and new step.
template <int Dim, class Real>
void Simulation<Dim, Real>::integrate_paper(Real dt) {
  const Real kick = leapfrog_started_ ? (last_dt_ + dt) / 2 : dt / 2;
  run_pass(fluid_, PaperLeapFrogPass<Dim, Real>{view(), kick, dt});
  leapfrog_started_ = true;
}

// The write-up's split with symplectic Euler (models/wcsph.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::integrate_wcsph(Real dt) {
  if (cfg_.density_evolution == DensityEvolution::Summation) {
    run_pass(fluid_, WcsphSymplecticEulerPass<Dim, Real>{view(), dt});
    return;
  }
  // Continuity density: the kick, then d rho / dt with the new velocities at the old positions (the rows
  // of this step), rho += dt d rho / dt, then the drift (models/continuity_density.hpp).
  run_pass(fluid_, WcsphKickPass<Dim, Real>{view(), dt});
  drho_.resize(p_.size());
  continuity_rate(cfg_, view(), fluid_);
  run_pass(fluid_, ContinuityIntegratePass<Dim, Real>{view(), dt});
  run_pass(fluid_, WcsphDriftPass<Dim, Real>{view(), dt});
}

// The box and the planes (integration/collisions.hpp).
template <int Dim, class Real>
void Simulation<Dim, Real>::apply_walls() {
  if (!cfg_.box.enabled && cfg_.planes.empty()) return;
  run_pass(fluid_, box_plane_collisions(cfg_, view()));
}

// After each step: the first particle (lowest index) with a non-finite quantity or outside the domain
// stops the run with a diagnosis.
template <int Dim, class Real>
void Simulation<Dim, Real>::check_state() {
  const auto check = stability_check(cfg_, view());
  const std::int64_t first = first_where(fluid_, check);
  if (first >= 0) report_unstable(first);
}

// The SimulationError of check_state for fluid particle `first` (the lowest failing index).
template <int Dim, class Real>
void Simulation<Dim, Real>::report_unstable(std::int64_t first) const {
  sync_host();
  std::ostringstream os;
  os.precision(9);
  os << "simulation unstable at step " << steps_ + 1 << " (t = " << time_
     << " s): " << describe_unstable(first);
  throw SimulationError(os.str());
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
  os << "particle " << i << " (id " << p_.id[i] << "): ";
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
  compute_forces_paper(due_list_, normal_set_);
  std::swap(p_.x, xs_);
  timings_.forces += sw.ms();

  sw.reset();
  per_particle_levels(cfg_, view(), due_list_, T, leapfrog_started_);
  leapfrog_started_ = true;
  apply_walls();
  check_state();
  std::int64_t next = earliest_tick(view(), fluid_);
  if (next == std::numeric_limits<std::int64_t>::max()) next = T + (std::int64_t{1} << L);
  last_dt_ = static_cast<Real>(next - T) * unit;
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
  // On the step count alone (checkpointed), never on the list rebuilds: see the header.
  if (cfg_.reorder_every > 0 && steps_ % cfg_.reorder_every == 0) {
    reorder_slots(fluid_);
    ++timings_.reorders;
    timings_.reorder += sw.ms();
    sw.reset();
  }
  inflow_mark();
  compute_neighbors();
  timings_.neighbors += sw.ms();

  sw.reset();
  filter_lists(fluid_);
  if (implicit_pressure(cfg_.model)) {
    step_dfsph(sw);
    return;
  }
  compute_density_pressure(fluid_);
  if (wall_states_) compute_wall_states();
  if (cfg_.model == Model::PaperMultiphase)
    compute_forces_paper(fluid_, fluid_);
  else
    compute_forces_wcsph();
  if (bodies_.any()) compute_body_loads();
  timings_.forces += sw.ms();

  sw.reset();
  const Real dt = choose_dt();
  if (cfg_.model == Model::PaperMultiphase)
    integrate_paper(dt);
  else
    integrate_wcsph(dt);
  inflow_hold(dt);
  apply_walls();
  check_state();
  time_ += dt;
  last_dt_ = dt;
  ++steps_;
  move_walls(time_);  // the walls where the next step's forces see them (and outputs, checkpoints)
  if (bodies_.any()) advance_bodies(dt);
  inflow_end_step(dt, true);
  timings_.integration += sw.ms();
}

// The rest of a DFSPH step after the rows (models/dfsph.hpp), then the walls and the check.
template <int Dim, class Real>
void Simulation<Dim, Real>::step_dfsph(Stopwatch& sw) {
  const std::size_t n = p_.size();
  timings_.density_evals += fluid_.size();
  timings_.force_evals += fluid_.size();
  vol_.resize(n);
  prho2_.resize(n);
  df_alpha_.resize(n);
  df_kappa_.resize(n);
  df_grad_.resize(nl_.indices.size());
  df_gsum_.resize(n);
  df_gwall_.resize(n);
  df_mv_.resize(n);
  df_mk_.resize(n);
  if (cfg_.dfsph.density_solver == DfsphDensitySolver::ConjugateGradient) {
    cg_v0_.resize(n);
    cg_s_.resize(n);
    cg_p_.resize(n);
    cg_ap_.resize(n);
    cg_active_.resize(n);
  }
  if (df_diameter_ == 0) df_diameter_ = dfsph_particle_diameter(view(), fluid_);
  // The threads split the fluid by pairs, not by particles (pass_driver.hpp): the same bits either way.
  balance(
      fluid_, static_cast<std::size_t>(max_threads()),
      [&](std::uint32_t i) { return std::uint64_t{within_count_[i]} + kBalanceParticleWeight; },
      fluid_split_);
  Real dt = 0;
  try {
    dt = cfg_.model == Model::Iisph
             ? iisph_step(cfg_, view(), fluid_split_, n, df_diameter_, dfsph_stats_, steps_ + 1)
             : dfsph_step(cfg_, view(), fluid_split_, n, df_diameter_, dfsph_stats_, steps_ + 1);
  } catch (const SimulationError& e) {
    report_diverged_solve(e);
  }
  timings_.forces += sw.ms();
  sw.reset();
  inflow_hold(dt);
  apply_walls();
  check_state();
  time_ += dt;
  last_dt_ = dt;
  ++steps_;
  move_walls(time_);  // the walls where the next step's forces see them (and outputs, checkpoints)
  inflow_end_step(dt, true);
  timings_.integration += sw.ms();
}

// The kind lists, rest densities and search radii from the particles (after a restore or a count change).
template <int Dim, class Real>
void Simulation<Dim, Real>::rebuild_kind_lists() {
  fluid_.clear();
  boundary_.clear();
  for (std::size_t i = 0; i < p_.size(); ++i) {
    rho0_[i] = cfg_.phases[static_cast<std::size_t>(p_.phase[i])].rest_density;
    const bool fluid = p_.kind[i] == kFluid;
    (fluid ? fluid_ : boundary_).push_back(static_cast<std::uint32_t>(i));
    bare_h_[i] = fluid ? p_.h[i] : Real(0);
    search_h_[i] = fluid ? p_.h[i] + skin_ : Real(0);
  }
  fluid_count_ = fluid_.size();
  lists_valid_ = false;
}

// Which emitters are active at the step's start (active_); true when one is.
template <int Dim, class Real>
bool Simulation<Dim, Real>::inflow_activity() {
  active_.assign(frames_.size(), 0);
  bool any = false;
  for (std::size_t e = 0; e < frames_.size(); ++e) {
    active_[e] = emitter_active(cfg_.inflow.emitters[e], double(time_)) ? 1 : 0;
    any = any || active_[e];
  }
  return any;
}

// The fluid particles in the buffer of an emitter active at the step's start (emitters.hpp), with their
// positions at that time.
template <int Dim, class Real>
void Simulation<Dim, Real>::inflow_mark() {
  holding_ = inflow_activity();
  if (!holding_) return;
  held_of_.resize(p_.size());
  held_x_.resize(p_.size());
  run_pass(fluid_, InflowMarkPass<Dim, Real>{p_.x.data(), held_of_.data(), held_x_.data(),
                                             emitter_planes_.data(), active_.data(), frames_.size()});
}

template <int Dim, class Real>
void Simulation<Dim, Real>::inflow_hold(Real dt) {
  if (!holding_) return;
  run_pass(fluid_, InflowHoldPass<Dim, Real>{p_.x.data(), p_.v.data(), held_of_.data(), held_x_.data(),
                                             emitter_planes_.data(), dt});
}

// After the step: the sinks' particles are removed, then the layers due are appended (oldest first, emitter
// by emitter), with new ids. An emitted particle is fluid of the emitter's phase at rest density and zero
// pressure, moving at U along the normal (the paper model's half-step velocity too), with zero solver state.
template <int Dim, class Real>
void Simulation<Dim, Real>::inflow_end_step(Real dt, bool maybe_in_sink) {
  if (!cfg_.inflow.any()) return;
  std::vector<V> xs;
  std::vector<std::int32_t> emitter_of;
  for (std::size_t e = 0; e < frames_.size(); ++e) {
    if (!active_[e]) continue;  // active at the step's start (inflow_activity)
    // The buffer moves U dt a step: more than a few spacings means a fixed step far too long for the inflow
    // (the Courant step keeps it below one), and a runaway count; stop with the numbers.
    const double travel = cfg_.inflow.emitters[e].velocity * double(dt);
    if (travel > 4 * cfg_.inflow.spacing)
      throw SimulationError("emitters[" + std::to_string(e) + "]: velocity * dt = " + std::to_string(travel) +
                            " m in one step, more than 4 particle spacings (" +
                            std::to_string(cfg_.inflow.spacing) + " m): shorten the time step");
    emit_layers(frames_[e], cfg_.inflow.emitters[e].velocity, double(dt), advance_[e], xs);
    emitter_of.resize(xs.size(), static_cast<std::int32_t>(e));
  }
  if (xs.empty() && !maybe_in_sink) return;
  // A device backend: the count changes here, on the host, from the device's particles (put back below).
  sync_host();
  const std::size_t n = p_.size();
  std::vector<std::uint8_t> keep;
  if (!cfg_.inflow.sinks.empty()) {
    keep.assign(n, 1);
    run_pass(fluid_, InflowSinkPass<Dim, Real>{
                         {p_.x.data(), cfg_.inflow.sinks.data(), cfg_.inflow.sinks.size()}, keep.data()});
    if (std::find(keep.begin(), keep.end(), std::uint8_t{0}) == keep.end()) keep.clear();
  }
  if (keep.empty() && xs.empty()) return;
  if (next_id_ + xs.size() > std::uint64_t{std::numeric_limits<std::uint32_t>::max()} + 1)
    throw SimulationError("emitters: the 2^32 particle ids are used up at t = " + std::to_string(time_) +
                          " s");
  change_count(keep, xs.size());
  const std::size_t first = p_.size() - xs.size();
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const std::size_t i = first + k;
    const auto& frame = frames_[static_cast<std::size_t>(emitter_of[k])];
    const std::int32_t ph = cfg_.inflow.emitters[static_cast<std::size_t>(emitter_of[k])].phase;
    const auto& phase = cfg_.phases[static_cast<std::size_t>(ph)];
    p_.x[i] = xs[k];
    p_.v[i] = frame.velocity;
    p_.m[i] = phase.mass;
    p_.rho[i] = phase.rest_density;
    p_.h[i] = cfg_.support;
    p_.color[i] = phase.color;
    p_.mu[i] = phase.viscosity;
    p_.phase[i] = ph;
    p_.kind[i] = kFluid;
    p_.id[i] = static_cast<std::uint32_t>(next_id_++);
  }
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
  edit(f_pressure_);
  edit(normal_);
  edit(wall_v_);
  edit(wall_self_rho_);
  edit(wall_a_);
  edit(drho_);
  edit(df_alpha_);
  edit(df_kappa_);
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

template <int Dim, class Real>
void Simulation<Dim, Real>::restore(Particles<Dim, Real> particles, const IntegratorState<Real>& state,
                                    const std::string& source, SolverState<Dim, Real> solver) {
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
    if (!state.emitter_advance.empty() && state.emitter_advance.size() != frames_.size())
      throw InputError(source + ": holds the state of " + std::to_string(state.emitter_advance.size()) +
                       " emitters, the scene has " + std::to_string(frames_.size()));
    for (const double a : state.emitter_advance)
      if (!(a >= 0 && a < 2 * cfg_.inflow.spacing))
        throw InputError(source + ": emitter advance " + std::to_string(a) + " is outside [0, 2 spacings)");
  } else if (const auto err = id_permutation_error(particles.id); !err.empty()) {
    throw InputError(source + ": " + err);
  }
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
  p_ = std::move(particles);
  // Scratch arrays hold nothing across steps: with another count they start afresh at the new size.
  if (f_pressure_.size() != n) f_pressure_.assign(n, V{});
  rho0_.resize(n);
  search_h_.resize(n);
  bare_h_.resize(n);
  rebuild_kind_lists();
  state_ = std::move(solver);
  if (inflow) {
    next_id_ = next_id;
    if (!state.emitter_advance.empty())
      advance_ = state.emitter_advance;
    else
      advance_.assign(frames_.size(), cfg_.inflow.spacing);
  }
  // Dynamic walls: their fixed density share, from the restored walls (kept weights, no reorder). Its
  // neighbour search is the first to see the positions: one beyond what a search can index (1e86 m) is
  // the file's fault, named as such (the Simulation is then not usable; the caller stops).
  set_moving_slots();
  set_body_slots(false);  // their particles are the checkpoint's; restore_bodies sets their states
  if (cfg_.wall_model == WallModel::Dynamic) {
    // Moving walls: the fixed share is that of the initial positions, as at construction.
    for (std::size_t k = 0; k < moving_.size(); ++k) p_.x[moving_[k]] = moving_x0_[k];
    try {
      init_boundary_weights();
    } catch (const CapacityError& e) {
      throw InputError(source + ": " + e.what());
    }
  }
  time_ = state.time;
  last_dt_ = state.last_dt;
  steps_ = state.steps;
  leapfrog_started_ = state.leapfrog_started;
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
  upload_to_device();
  backend_ = b;
}

// The particles and, for dynamic walls, their fixed wall-wall densities (init_boundary_weights).
template <int Dim, class Real>
void Simulation<Dim, Real>::upload_to_device() {
  device_->upload(p_);
  if (cfg_.wall_model == WallModel::Dynamic && !boundary_.empty())
    device_->upload_wall_self_density(wall_self_rho_);
  if (!moving_.empty() || !wall_a_.empty())
    device_->upload_wall_motion(moving_, moving_x0_, moving_motion_, wall_a_);
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
  DeviceStepInput<Real> in{time_, last_dt_, leapfrog_started_};
  if (inflow_activity()) in.emitters_active = active_.data();
  if (implicit_pressure(cfg_.model)) {
    if (df_diameter_ == 0) df_diameter_ = dfsph_particle_diameter(view(), fluid_);  // m, rho0: on the host
    in.step = steps_ + 1;
    in.dfsph_diameter = df_diameter_;
    in.dfsph = &dfsph_stats_;
  }
  DeviceStepResult<Real> r{};
  try {
    r = device_->step(in);
  } catch (const SimulationError& e) {
    host_stale_ = true;  // the device's particles, as the diverged solve left them
    report_diverged_solve(e);
  }
  if (cfg_.model == Model::PaperMultiphase) leapfrog_started_ = true;
  host_stale_ = true;
  timings_.neighbors += r.neighbors_ms;
  timings_.forces += r.forces_ms;
  timings_.integration += r.integration_ms;
  ++timings_.list_builds;
  timings_.density_evals += fluid_count_;
  timings_.force_evals += fluid_count_;
  if (r.first_bad >= 0) report_unstable(r.first_bad);  // copies the particles back to describe it
  time_ += r.dt;
  last_dt_ = r.dt;
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
