// The Simulation across ranks (docs/distributed.md, issue 49): what a step does beyond one process. Each
// rank holds the particles it owns and the halo copies its rows need, in id order (distributed/
// rank_domain.hpp); every step moves particles to their owners first; a pass's outputs that a neighbour
// reads are refreshed on the copies right after it (share_*); the step size and the stability check are
// agreed over the ranks (simulation.cpp's HostStepContext::agree_dt and check_state).
#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/distributed/rank_domain.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/verlet_rows.hpp"

namespace cellsph {

namespace {

constexpr std::uint8_t kFluidKind = static_cast<std::uint8_t>(ParticleKind::Fluid);

// A rank's arrays that travel with its particles: every particle field, the solver state and the dynamic
// walls' fixed density, as one field list.
template <int Dim, class Real>
struct TravellingArrays {
  Particles<Dim, Real>& p;
  SolverState<Dim, Real>& s;
  std::vector<Real>& wall_self_rho;
  std::vector<Vec<Dim, Real>>& x;
  std::vector<std::uint32_t>& id;

  TravellingArrays(Particles<Dim, Real>& p_in, SolverState<Dim, Real>& s_in, std::vector<Real>& self_rho)
      : p(p_in), s(s_in), wall_self_rho(self_rho), x(p_in.x), id(p_in.id) {}
  template <class F>
  void for_each_field(F&& fn) const {
    p.for_each_field(fn);
    s.for_each_field(fn);
    fn(std::string_view("wall_self_rho"), wall_self_rho);
  }
  [[nodiscard]] std::size_t size() const { return p.size(); }
  void resize(std::size_t n) const {
    for_each_field([n](std::string_view, auto& field) { field.resize(n); });
  }
};

}  // namespace

// What the step across ranks runs so far; everything else is refused at the start, every key named.
template <int Dim, class Real>
void Simulation<Dim, Real>::check_distributable() const {
  std::vector<std::string> not_yet;
  if (cfg_.model == Model::Dfsph && cfg_.dfsph.density_solver == DfsphDensitySolver::ConjugateGradient)
    not_yet.push_back("/solver/dfsph/density_solver \"cg\" (\"jacobi\" runs)");
  if (cfg_.time.mode == TimeStepping::PerParticle) not_yet.push_back("/time/stepping \"per-particle\"");
  if (cfg_.reorder_every > 0)
    not_yet.push_back("/neighbors/reorder_every " + std::to_string(cfg_.reorder_every) + " (only 0)");
  if (cfg_.inflow.any()) not_yet.push_back("/emitters and /sinks");
  if (cfg_.wall_model == WallModel::VolumeMap) not_yet.push_back("/boundary/model \"volume-map\"");
  if (backend_ != Backend::Cpu) not_yet.push_back("--backend " + std::string(backend_name(backend_)));
  if (not_yet.empty()) return;
  std::ostringstream os;
  os << "a run across MPI ranks runs every model with global steps on the CPU, but not yet "
        "(docs/distributed.md) what this scene has: ";
  for (std::size_t k = 0; k < not_yet.size(); ++k) os << (k ? "; " : "") << not_yet[k];
  os << ". Run it as one process (without mpirun), or change those keys with --set";
  throw InputError(os.str());
}

template <int Dim, class Real>
void Simulation<Dim, Real>::distribute(const distributed::Communicator& comm) {
  if (comm.size() <= 1) return;
  check_distributable();
  V lo = p_.x.empty() ? V{} : p_.x[0];
  for (const V& x : p_.x)
    for (int a = 0; a < Dim; ++a) lo[a] = std::min(lo[a], x[a]);
  // The halo's margin beyond the support: half of it (or the Verlet skin, if longer). A wider margin keeps
  // the domain for more steps (a rebuild moves and sorts every particle) and refreshes more copies each
  // step: on the default scene on 2 ranks, a margin of 0.15 h rebuilt every 3-4 steps and took 10-20%
  // longer than 0.5 h (docs/benchmarks.md, "A run across MPI ranks").
  domain_margin_ = std::max(skin_, cfg_.support / 2);
  // The rows reach the support, and a floating body's particles their contact distance.
  const double reach =
      std::max(double(cfg_.support), bodies_.any() ? cfg_.rigid_bodies.contact_distance : 0.0);
  domain_ = std::make_unique<distributed::RankDomain<Dim, Real>>(comm, lo, reach + double(domain_margin_));
  global_fluid_count_ = fluid_count_;
  rank_stats_ = RankStats{};
  rank_stats_.ranks = comm.size();
  wall_self_rho_.resize(p_.size());  // travels with every particle (0 but for dynamic walls)
  rebuild_domain(true);
  gather_for_output();
}

template <int Dim, class Real>
void Simulation<Dim, Real>::rebuild_domain(bool first) {
  TravellingArrays<Dim, Real> arrays(p_, state_, wall_self_rho_);
  // The start's split weighs a fluid particle as four wall particles (its row's passes against a wall's
  // state pass); later rebuilds keep the cuts unless balance_domain cut again by the measured work.
  if (first)
    domain_->start(arrays, [&](std::size_t i) { return p_.kind[i] == kFluidKind ? 4 : 1; });
  else
    domain_->rebuild(arrays);
  const std::size_t n = p_.size();
  rho0_.assign(n, Real(0));
  search_h_.assign(n, Real(0));
  bare_h_.assign(n, Real(0));
  // The per-slot arrays a step writes before it reads them, but only for some kinds: as a single-process
  // run holds them for particles no pass writes (0), not another particle's value left in the slot.
  for (auto* a : {&vol_, &prho2_}) a->assign(n, Real(0));
  if (!wall_v_.empty()) wall_v_.assign(n, V{});
  rebuild_kind_lists();
  // The moving walls this rank owns, at the clock's time: their positions and velocities (the same bits as
  // those that travelled) and their accelerations, which do not travel.
  set_moving_slots();
  move_walls(time_);
  set_body_slots(true);  // their search radius, and placed again from the same states (the same bits)
  x_domain_ = p_.x;
}

// The halo holds every particle within the support plus the margin of an owned one, as they stood at the
// rebuild. While no particle has moved more than 0.45 of the margin since (the largest displacement over
// every rank), a pair within the support now was within support + 0.9 margin then: the halo still holds
// every row's particles, and only the copies' positions and velocities need their owners' new values.
template <int Dim, class Real>
void Simulation<Dim, Real>::update_domain() {
  const MaxDisplacementPass<Dim, Real> disp{view(), x_domain_.data()};
  Real local = reduce_max(fluid_, MaxValue<Real>{}, disp).value;
  if (moving_.any()) local = std::max(local, reduce_max(moving_.slots(), MaxValue<Real>{}, disp).value);
  if (bodies_.any()) local = std::max(local, reduce_max(bodies_.slots(), MaxValue<Real>{}, disp).value);
  const Real d2 = domain_->max(local);
  const Real limit = Real(0.45) * domain_margin_;
  if (d2 <= limit * limit) {
    domain_->refresh(p_.x, p_.v);
    return;
  }
  balance_domain();
  rebuild_domain(false);
  ++rank_stats_.rebuilds;
}

// A fluid particle's work is its row's pairs plus four (its own loads and stores, as the threads' split
// weighs it), a wall particle's one (its state pass); a halo copy's none.
template <int Dim, class Real>
std::int64_t Simulation<Dim, Real>::owned_work(std::size_t i) const {
  if (p_.kind[i] != kFluidKind) return 1;
  return std::int64_t{4} + (i < within_count_.size() ? std::int64_t{within_count_[i]} : 0);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::balance_domain() {
  std::int64_t work = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (domain_->owned()[i]) work += owned_work(i);
  const std::vector<std::int64_t> all = domain_->comm().all_gather({work});
  std::int64_t busiest = 0, total = 0;
  for (const std::int64_t w : all) {
    busiest = std::max(busiest, w);
    total += w;
  }
  const double mean = double(total) / double(all.size());
  rank_stats_.imbalance = mean > 0 ? double(busiest) / mean - 1 : 0;
  rank_stats_.max_imbalance = std::max(rank_stats_.max_imbalance, rank_stats_.imbalance);
  if (rank_stats_.imbalance <= cfg_.rebalance_threshold) return;
  TravellingArrays<Dim, Real> arrays(p_, state_, wall_self_rho_);
  domain_->recut(arrays, [&](std::size_t i) { return owned_work(i); });
  ++rank_stats_.rebalances;
}

template <int Dim, class Real>
void Simulation<Dim, Real>::share_density() {
  if (!domain_) return;
  domain_->refresh(p_.rho, p_.p, vol_, prho2_);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::share_wall_states() {
  if (!domain_) return;
  domain_->refresh(p_.rho, p_.p, vol_, prho2_, wall_v_);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::share_velocity() {
  if (domain_) domain_->refresh(p_.v);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::share_body_loads() {
  struct Entry {
    std::uint32_t id;
    std::int32_t body;
    Vec<Dim, double> f;
    V x;
  };
  const auto& slots = bodies_.slots();
  const auto& f = bodies_.forces();
  const auto& body = bodies_.body_of_body_particle();
  std::vector<std::byte> mine(slots.size() * sizeof(Entry));
  for (std::size_t k = 0; k < slots.size(); ++k) {
    const Entry e{p_.id[slots[k]], body[k], f[k], p_.x[slots[k]]};
    std::memcpy(mine.data() + k * sizeof(Entry), &e, sizeof(Entry));
  }
  const std::vector<std::byte> all = domain_->all_gather(mine);
  std::vector<Entry> entries(all.size() / sizeof(Entry));
  std::memcpy(entries.data(), all.data(), entries.size() * sizeof(Entry));
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.id < b.id; });
  std::vector<std::int32_t> bodies(entries.size());
  std::vector<Vec<Dim, double>> forces(entries.size());
  std::vector<V> xs(entries.size());
  for (std::size_t k = 0; k < entries.size(); ++k) {
    bodies[k] = entries[k].body;
    forces[k] = entries[k].f;
    xs[k] = entries[k].x;
  }
  bodies_.sum_loads_of(bodies, forces, xs);
}

template <int Dim, class Real>
void Simulation<Dim, Real>::gather_for_output() {
  if (!domain_) return;
  TravellingArrays<Dim, Real> arrays(p_, state_, wall_self_rho_);
  std::vector<Real> self_rho;
  TravellingArrays<Dim, Real> out(shown_, shown_state_, self_rho);
  domain_->gather_to_root(arrays, out);
}

#define CELLSPH_SIMULATION_RANKS(D, R)                                          \
  template void Simulation<D, R>::check_distributable() const;                  \
  template void Simulation<D, R>::distribute(const distributed::Communicator&); \
  template void Simulation<D, R>::rebuild_domain(bool);                         \
  template void Simulation<D, R>::update_domain();                              \
  template std::int64_t Simulation<D, R>::owned_work(std::size_t) const;        \
  template void Simulation<D, R>::balance_domain();                             \
  template void Simulation<D, R>::share_density();                              \
  template void Simulation<D, R>::share_wall_states();                          \
  template void Simulation<D, R>::share_velocity();                             \
  template void Simulation<D, R>::share_body_loads();                           \
  template void Simulation<D, R>::gather_for_output();
CELLSPH_SIMULATION_RANKS(2, float)
CELLSPH_SIMULATION_RANKS(2, double)
CELLSPH_SIMULATION_RANKS(3, float)
CELLSPH_SIMULATION_RANKS(3, double)
#undef CELLSPH_SIMULATION_RANKS

}  // namespace cellsph
