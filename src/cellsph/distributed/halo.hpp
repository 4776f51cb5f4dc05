#pragma once
// The halo of a rank (issue 49 item 3, docs/distributed.md): copies of the other ranks' particles within
// a radius (the support plus the Verlet skin) of any particle it owns, so that every row of an owned
// particle is complete on its rank. The curve is the Z-order of a grid of cells (CurveGrid); an aligned
// cube of 2^k x 2^k (x 2^k) cells is one contiguous range of keys, so with k the least such that the cube
// is at least the radius wide, a particle within the radius of another lies in the same cube or one of
// the 3^Dim - 1 around it, and the ranks that may need a particle are the owners of those cubes' key
// ranges (contiguous ranks, as the ranges are). A rank then holds its particles and the halo sorted by
// id together: each row in the single-process order (migrate.hpp).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <vector>

#include "cellsph/core/vec.hpp"
#include "cellsph/distributed/communicator.hpp"
#include "cellsph/distributed/curve_split.hpp"
#include "cellsph/distributed/migrate.hpp"
#include "cellsph/solver/cell_order.hpp"

namespace cellsph::distributed {

// The grid whose Z-order is the curve: cells of `cell` [m] from `lo`, `bits` bits a coordinate (points
// outside are clamped to the grid's faces).
template <int Dim>
struct CurveGrid {
  double lo[3] = {0, 0, 0};
  double cell = 1;
  int bits = 64 / Dim;

  template <class Real>
  void cell_of(const Vec<Dim, Real>& x, std::uint64_t (&c)[Dim]) const {
    const double top = std::ldexp(1.0, bits) - 1;
    for (int a = 0; a < Dim; ++a)
      c[a] = static_cast<std::uint64_t>(std::clamp(std::floor((double(x[a]) - lo[a]) / cell), 0.0, top));
  }
  template <class Real>
  std::uint64_t key(const Vec<Dim, Real>& x) const {
    std::uint64_t c[Dim];
    cell_of(x, c);
    return morton_key<Dim>(c);
  }
};

// For each rank, the particles among x's first `owned` that it may need within `radius` (never this rank
// `me`): ascending indices.
template <int Dim, class Real>
std::vector<std::vector<std::size_t>> halo_sends(std::span<const Vec<Dim, Real>> x, std::size_t owned,
                                                 const CurveGrid<Dim>& grid, const CurveSplit& split,
                                                 double radius, int me) {
  int k = 0;  // the cube of 2^k cells a side at least `radius` wide
  while (k < grid.bits && std::ldexp(grid.cell, k) < radius) ++k;
  const std::uint64_t last_cube = (std::uint64_t{1} << (grid.bits - k)) - 1;
  std::vector<std::vector<std::size_t>> out(static_cast<std::size_t>(split.ranks()));
  constexpr int kCubes = Dim == 2 ? 9 : 27;            // the particle's cube and those around it
  std::vector<std::size_t> marked(out.size(), owned);  // the particle last added for each rank
  for (std::size_t i = 0; i < owned; ++i) {
    std::uint64_t c[Dim];
    grid.cell_of(x[i], c);
    for (int around = 0; around < kCubes; ++around) {
      std::uint64_t cube[Dim];
      bool inside = true;
      int code = around;
      for (int a = 0; a < Dim; ++a, code /= 3) {
        const std::int64_t b = static_cast<std::int64_t>(c[a] >> k) + code % 3 - 1;
        inside = inside && b >= 0 && static_cast<std::uint64_t>(b) <= last_cube;
        cube[a] = static_cast<std::uint64_t>(b) << k;
      }
      if (!inside) continue;
      const std::uint64_t first = morton_key<Dim>(cube);
      const std::uint64_t span = std::uint64_t{1} << (Dim * k);
      for (int r = split.owner(first); r <= split.owner(first + span - 1); ++r) {
        if (r == me || marked[static_cast<std::size_t>(r)] == i) continue;
        marked[static_cast<std::size_t>(r)] = i;
        out[static_cast<std::size_t>(r)].push_back(i);
      }
    }
  }
  return out;
}

// Which slots of a rank's arrays go to each rank when a field is refreshed (its owned particles in the
// other ranks' halos), and which take what each rank sends (its halo copies), in the same order on both
// sides. Valid until the particles move or the halo is rebuilt.
struct HaloPlan {
  std::vector<std::vector<std::size_t>> send, receive;
};

// Appends to p (its owned particles) copies of the particles the other ranks send it (`sends`: this rank's
// halo_sends), then sorts owned and halo together by id. `owned_out`, in the new order: 1 for a particle
// this rank owns, 0 for a halo copy. Returns the plan that refreshes one field of the copies.
template <class Soa>
HaloPlan add_halo(Soa& p, const std::vector<std::vector<std::size_t>>& sends, const Communicator& comm,
                  std::vector<std::uint8_t>& owned_out) {
  std::vector<std::vector<std::byte>> to_rank(sends.size());
  for (std::size_t r = 0; r < sends.size(); ++r) pack(p, std::span<const std::size_t>(sends[r]), to_rank[r]);
  std::vector<std::size_t> from;
  const std::vector<std::byte> in = comm.all_to_all(to_rank, from);
  const std::size_t owned = p.size();
  const auto counts = unpack_append(p, in, from);
  const auto order = sort_by_id(p);
  std::vector<std::size_t> slot_of(order.size());  // where each particle of the unsorted arrays went
  owned_out.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    slot_of[order[k]] = k;
    owned_out[k] = order[k] < owned ? 1 : 0;
  }
  HaloPlan plan;
  plan.send.resize(sends.size());
  plan.receive.resize(counts.size());
  for (std::size_t r = 0; r < sends.size(); ++r)
    for (const std::size_t i : sends[r]) plan.send[r].push_back(slot_of[i]);
  std::size_t next = owned;
  for (std::size_t r = 0; r < counts.size(); ++r)
    for (std::uint64_t c = 0; c < counts[r]; ++c) plan.receive[r].push_back(slot_of[next++]);
  return plan;
}

// The halo copies of some fields (each given by its first element, one entry per slot) brought up to date
// from their owners, after a pass wrote them for the owned particles: one all-to-all exchange, each
// particle's values together.
template <class... T>
void refresh_halo_fields(const HaloPlan& plan, const Communicator& comm, T*... fields) {
  static_assert((std::is_trivially_copyable_v<T> && ...),
                "a field sent to another rank must be trivially copyable");
  std::vector<std::vector<std::byte>> to_rank(plan.send.size());
  for (std::size_t r = 0; r < plan.send.size(); ++r)
    for (const std::size_t k : plan.send[r]) (migrate_detail::append(to_rank[r], fields[k]), ...);
  std::vector<std::size_t> from;
  const std::vector<std::byte> in = comm.all_to_all(to_rank, from);
  constexpr std::size_t bytes = (sizeof(T) + ...);
  std::size_t at = 0;
  for (std::size_t r = 0; r < plan.receive.size(); ++r) {
    CELLSPH_CHECK(from[r] == plan.receive[r].size() * bytes,
                  "refresh_halo: " << from[r] << " bytes from rank " << r << " for " << plan.receive[r].size()
                                   << " copies");
    for (const std::size_t k : plan.receive[r])
      ((std::memcpy(&fields[k], in.data() + at, sizeof(T)), at += sizeof(T)), ...);
  }
}

// The same for one field.
template <class T>
void refresh_halo(std::vector<T>& field, const HaloPlan& plan, const Communicator& comm) {
  refresh_halo_fields(plan, comm, field.data());
}

}  // namespace cellsph::distributed
