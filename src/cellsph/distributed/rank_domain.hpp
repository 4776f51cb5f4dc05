#pragma once
// One rank's part of a run across ranks (issue 49, docs/distributed.md): which particles it owns, the
// copies of the other ranks' particles its rows need (the halo), and the collectives a step makes. The
// Simulation holds one when the run spans several ranks and calls it at the start of each step (the
// particles to their owners by the curve's cuts, the halo rebuilt), after each pass whose output a
// neighbour reads (refresh), for the step size (min) and the stability check (lowest, message), and
// for the outputs (gather_to_root). A rank's arrays, owned and halo together, are in id order, so every
// row runs in the single-process order and each owned particle gets the single-process bits.
//
// `Soa` is a struct of arrays with the particles' field list (solver/particles.hpp: for_each_field, size,
// resize, id), every field one trivially copyable element per particle.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "cellsph/core/vec.hpp"
#include "cellsph/distributed/communicator.hpp"
#include "cellsph/distributed/curve_split.hpp"
#include "cellsph/distributed/halo.hpp"
#include "cellsph/distributed/migrate.hpp"

namespace cellsph::distributed {

template <int Dim, class Real>
class RankDomain {
 public:
  using V = Vec<Dim, Real>;

  // The curve's grid from `lo` (the particles' lower corner: points below it share the grid's first
  // cells), cells `radius` wide: the support plus the Verlet skin, the reach of a row.
  RankDomain(Communicator comm, const V& lo, double radius) : comm_(comm), radius_(radius) {
    for (int a = 0; a < Dim; ++a) grid_.lo[a] = double(lo[a]);
    grid_.cell = radius;
    grid_.bits = Dim == 2 ? 31 : 21;
  }

  [[nodiscard]] const Communicator& comm() const { return comm_; }
  [[nodiscard]] int ranks() const { return comm_.size(); }
  [[nodiscard]] const CurveSplit& split() const { return split_; }
  // Per slot of the rank's arrays: 1 owned, 0 a halo copy.
  [[nodiscard]] const std::vector<std::uint8_t>& owned() const { return owned_; }

  // The start: every rank holds every particle (the same arrays, built from the same scene). The cuts
  // come from the particles dealt round robin (each rank counts its share's weights, the histograms are
  // summed), then each rank keeps the particles it owns and receives its halo. `weight(i)` > 0: particle
  // i's work.
  template <class Soa, class Weight>
  void start(Soa& p, Weight&& weight) {
    const std::size_t n = p.size();
    const auto me = static_cast<std::size_t>(comm_.rank()), ranks = static_cast<std::size_t>(comm_.size());
    std::vector<std::uint64_t> keys;
    std::vector<std::int64_t> weights;
    for (std::size_t i = me; i < n; i += ranks) {
      keys.push_back(grid_.key(p.x[i]));
      weights.push_back(static_cast<std::int64_t>(weight(i)));
    }
    cut(keys, weights);
    std::vector<std::size_t> mine;
    for (std::size_t i = 0; i < n; ++i)
      if (split_.owner(grid_.key(p.x[i])) == comm_.rank()) mine.push_back(i);
    keep_only(p, mine);
    add_own_halo(p);
  }

  // The curve cut again by the owned particles' work (`weight(i)` > 0 for each owned slot i): the ranks'
  // shares even out at the next rebuild, which moves the particles by the new cuts.
  template <class Soa, class Weight>
  void recut(const Soa& p, Weight&& weight) {
    std::vector<std::uint64_t> keys;
    std::vector<std::int64_t> weights;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!owned_[i]) continue;
      keys.push_back(grid_.key(p.x[i]));
      weights.push_back(static_cast<std::int64_t>(weight(i)));
    }
    cut(keys, weights);
  }

  // Each step: the halo dropped, the owned particles sent to the ranks that own their keys now (the cuts
  // stay), and the halo received again for the new positions.
  template <class Soa>
  void rebuild(Soa& p) {
    std::vector<std::size_t> mine;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (owned_[i]) mine.push_back(i);
    keep_only(p, mine);
    std::vector<int> dest(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) dest[i] = split_.owner(grid_.key(p.x[i]));
    migrate(p, dest, comm_);
    add_own_halo(p);
  }

  // The halo copies of these fields from their owners, after a pass wrote them for the owned particles:
  // one exchange, each particle's values together.
  template <class... T>
  void refresh(std::vector<T>&... fields) const {
    refresh(fields.data()...);
  }
  // The same for arrays given by their first element (a view's arrays).
  template <class... T>
  void refresh(T*... fields) const {
    refresh_halo_fields(plan_, comm_, fields...);
  }

  // The smallest of every rank's value (a step size: each rank's is a monotone function of its maximum,
  // so the smallest is the single-process step, bit for bit).
  [[nodiscard]] Real min(Real value) const { return static_cast<Real>(-comm_.max(-double(value))); }
  [[nodiscard]] Real max(Real value) const { return static_cast<Real>(comm_.max(double(value))); }
  [[nodiscard]] std::uint64_t sum(std::uint64_t value) const {
    auto v = static_cast<std::int64_t>(value);
    comm_.sum_in_place(&v, 1);
    return static_cast<std::uint64_t>(v);
  }

  // The lowest of every rank's candidate (an id, or -1 for none): -1 when no rank has one.
  [[nodiscard]] std::int64_t lowest(std::int64_t mine) const {
    std::int64_t best = -1;
    for (const std::int64_t v : comm_.all_gather({mine}))
      if (v >= 0 && (best < 0 || v < best)) best = v;
    return best;
  }

  // The one non-empty text among the ranks' (the rank that found what it says), on every rank.
  [[nodiscard]] std::string message(const std::string& mine) const {
    std::vector<std::vector<std::byte>> to_rank(static_cast<std::size_t>(comm_.size()));
    for (auto& m : to_rank) {
      const auto* b = reinterpret_cast<const std::byte*>(mine.data());
      m.assign(b, b + mine.size());
    }
    std::vector<std::size_t> from;
    const std::vector<std::byte> in = comm_.all_to_all(to_rank, from);
    return std::string(reinterpret_cast<const char*>(in.data()), in.size());
  }

  // Every rank's bytes, concatenated in rank order, on every rank.
  [[nodiscard]] std::vector<std::byte> all_gather(const std::vector<std::byte>& mine) const {
    std::vector<std::vector<std::byte>> to_rank(static_cast<std::size_t>(comm_.size()), mine);
    std::vector<std::size_t> from;
    return comm_.all_to_all(to_rank, from);
  }

  // Every rank's owned particles, on rank 0 in id order (the other ranks' `out` ends empty).
  template <class Soa>
  void gather_to_root(const Soa& p, Soa& out) const {
    std::vector<std::size_t> mine;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (owned_[i]) mine.push_back(i);
    std::vector<std::vector<std::byte>> to_rank(static_cast<std::size_t>(comm_.size()));
    pack(p, std::span<const std::size_t>(mine), to_rank[0]);
    std::vector<std::size_t> from;
    const std::vector<std::byte> in = comm_.all_to_all(to_rank, from);
    out.resize(0);
    if (comm_.rank() != 0) return;
    unpack_append(out, in, from);
    sort_by_id(out);
  }

 private:
  static constexpr double kTolerance = 0.02;  // each rank's work within 2% of its share, where keys allow

  // The cuts from this rank's share of the keys and weights (the histograms are summed over the ranks).
  void cut(const std::vector<std::uint64_t>& keys, const std::vector<std::int64_t>& weights) {
    split_ = split_curve(keys, weights, Dim * grid_.bits, comm_.size(), kTolerance,
                         [this](std::int64_t* v, int count) { comm_.sum_in_place(v, count); });
  }

  // p reduced to the particles `which` (ascending), every field.
  template <class Soa>
  static void keep_only(Soa& p, const std::vector<std::size_t>& which) {
    p.for_each_field([&](std::string_view, auto& field) {
      for (std::size_t k = 0; k < which.size(); ++k) field[k] = field[which[k]];
    });
    p.resize(which.size());
  }

  template <class Soa>
  void add_own_halo(Soa& p) {
    const auto sends = halo_sends<Dim, Real>(std::span<const V>(p.x.data(), p.size()), p.size(), grid_,
                                             split_, radius_, comm_.rank());
    plan_ = add_halo(p, sends, comm_, owned_);
  }

  Communicator comm_;
  double radius_;
  CurveGrid<Dim> grid_;
  CurveSplit split_;
  HaloPlan plan_;
  std::vector<std::uint8_t> owned_;
};

}  // namespace cellsph::distributed
