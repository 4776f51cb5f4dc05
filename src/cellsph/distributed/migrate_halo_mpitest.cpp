// Particles move to the ranks the curve's cuts give them, every field intact, in id order (issue 49 item
// 2), and each rank's halo holds every particle its rows need, so a sum over a row has the single-process
// bits (item 3). The whole set is made from a seed on every rank; what each rank must hold is worked out
// from that whole set in one process (each particle's key, the cuts over all keys, its owner, brute-force
// distances, the single-process sums), not by the code under test.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <set>
#include <vector>

#include "cellsph/distributed/communicator.hpp"
#include "cellsph/distributed/curve_split.hpp"
#include "cellsph/distributed/halo.hpp"
#include "cellsph/distributed/migrate.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/cell_order.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph::distributed {
namespace {

// 6000 particles in the unit cube, crowded towards one corner (so equal work is not equal volume), every
// field filled with distinct values, ids 0..n-1.
Particles<3, double> whole_set() {
  std::mt19937_64 rng(4949);
  std::uniform_real_distribution<double> u(0, 1);
  Particles<3, double> p;
  p.resize(6000);
  std::uint32_t next = 0;
  p.for_each_field([&](std::string_view, auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    for (auto& e : field) {
      // Every byte of every element from the generator: no two particles alike in any field.
      std::vector<unsigned char> bytes(sizeof(T));
      for (auto& b : bytes) b = static_cast<unsigned char>(rng() & 0x7f);
      std::memcpy(&e, bytes.data(), sizeof(T));
    }
  });
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double a = u(rng);
    p.x[i] = {a * a * u(rng), a * u(rng), a};
    p.id[i] = next++;
  }
  return p;
}

// Particle i of `from`, every field, appended to `to`.
void append_particle(Particles<3, double>& to, const Particles<3, double>& from, std::size_t i) {
  const std::size_t k = to.size();
  to.resize(k + 1);
  to.for_each_field([&](std::string_view name, auto& field) {
    from.for_each_field([&](std::string_view n2, const auto& f2) {
      if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::decay_t<decltype(f2)>>) {
        if (name == n2) field[k] = f2[i];
      }
    });
  });
}

// The particle's key on the curve: the Z-order of its cell, 2^20 cells an axis.
std::uint64_t key_of(const Vec<3, double>& x) {
  std::uint64_t c[3];
  for (int a = 0; a < 3; ++a) c[a] = static_cast<std::uint64_t>(x[a] * double(1 << 20));
  return morton_key<3>(c);
}

TEST(Migrate, ParticlesReachTheirRanksWithEveryFieldInIdOrder) {
  const auto w = world();
  const auto all = whole_set();
  // Where each particle belongs: the cuts over every key at once, with one process's sum.
  std::vector<std::uint64_t> keys(all.size());
  std::vector<std::int64_t> weight(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    keys[i] = key_of(all.x[i]);
    weight[i] = 1 + static_cast<std::int64_t>(i % 7);
  }
  const auto cuts = split_curve(keys, weight, 60, w.size(), 0.01, [](std::int64_t*, int) {});
  // Dealt round robin, then moved by the cuts each rank finds from its own share.
  Particles<3, double> mine;
  std::vector<std::uint64_t> my_keys;
  std::vector<std::int64_t> my_weight;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (static_cast<int>(i % std::size_t(w.size())) == w.rank()) {
      append_particle(mine, all, i);
      my_keys.push_back(keys[i]);
      my_weight.push_back(weight[i]);
    }
  const auto split = split_curve(my_keys, my_weight, 60, w.size(), 0.01,
                                 [&w](std::int64_t* v, int n) { w.sum_in_place(v, n); });
  ASSERT_EQ(split.start, cuts.start);
  std::vector<int> dest(mine.size());
  for (std::size_t k = 0; k < mine.size(); ++k) dest[k] = split.owner(my_keys[k]);
  migrate(mine, dest, w);
  // This rank holds exactly the particles whose key it owns, ascending by id, each field's bytes intact.
  std::vector<std::size_t> want;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (cuts.owner(keys[i]) == w.rank()) want.push_back(i);
  ASSERT_EQ(mine.size(), want.size()) << "rank " << w.rank();
  for (std::size_t k = 0; k < want.size(); ++k) {
    ASSERT_EQ(mine.id[k], all.id[want[k]]) << "rank " << w.rank() << ", slot " << k;
    mine.for_each_field([&](std::string_view name, const auto& field) {
      all.for_each_field([&](std::string_view n2, const auto& f2) {
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::decay_t<decltype(f2)>>) {
          if (name == n2) {
            EXPECT_EQ(std::memcmp(&field[k], &f2[want[k]], sizeof(field[k])), 0)
                << name << ", id " << mine.id[k];
          }
        }
      });
    });
  }
  std::int64_t count = static_cast<std::int64_t>(mine.size());
  w.sum_in_place(&count, 1);
  EXPECT_EQ(count, static_cast<std::int64_t>(all.size()));
}

// This rank's share of the whole set after the cuts and the move: the particles whose key it owns.
Particles<3, double> my_share(const Particles<3, double>& all, const CurveGrid<3>& grid, CurveSplit& split) {
  const auto w = world();
  Particles<3, double> mine;
  std::vector<std::uint64_t> keys;
  std::vector<std::int64_t> weight;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (static_cast<int>(i % std::size_t(w.size())) == w.rank()) {
      append_particle(mine, all, i);
      keys.push_back(grid.key(all.x[i]));
      weight.push_back(1);
    }
  split =
      split_curve(keys, weight, 60, w.size(), 0.01, [&w](std::int64_t* v, int n) { w.sum_in_place(v, n); });
  std::vector<int> dest(mine.size());
  for (std::size_t k = 0; k < mine.size(); ++k) dest[k] = split.owner(keys[k]);
  migrate(mine, dest, w);
  return mine;
}

// rho_i = sum of m_j W(|x_i - x_j|) over the rows of `search` (ascending j), for the particles `which`.
std::vector<double> densities(const Particles<3, double>& p, NeighborList& rows,
                              const std::vector<std::size_t>& which, bool backwards) {
  const Poly6Kernel<3, double> kernel(0.05);
  std::vector<double> rho;
  for (const std::size_t i : which) {
    double sum = 0;
    const std::size_t n = rows.count(i);
    for (std::size_t t = 0; t < n; ++t) {
      const std::uint32_t j = rows.begin(i)[backwards ? n - 1 - t : t];
      sum += p.m[j] * kernel.W2(norm2(p.x[i] - p.x[j]));
    }
    rho.push_back(sum);
  }
  return rho;
}

TEST(Halo, RowsAreCompleteSumToTheSingleProcessBitsAndRefreshReachesTheCopies) {
  const auto w = world();
  auto all = whole_set();
  for (std::size_t i = 0; i < all.size(); ++i) all.m[i] = 1e-3 * (1 + double(i % 13));
  CurveGrid<3> grid;
  grid.cell = 1.0 / double(1 << 20);
  grid.bits = 20;
  const double radius = 0.05;
  CurveSplit split;
  auto p = my_share(all, grid, split);
  const std::size_t owned = p.size();
  const auto sends = halo_sends<3, double>(p.x, owned, grid, split, radius, w.rank());
  std::vector<std::uint8_t> mine;
  const auto plan = add_halo(p, sends, w, mine);
  ASSERT_EQ(mine.size(), p.size());
  for (std::size_t k = 1; k < p.size(); ++k) ASSERT_LT(p.id[k - 1], p.id[k]);  // one copy each, in id order
  // Complete: every particle of the whole set within the radius of an owned one is here (brute force).
  const std::set<std::uint32_t> here(p.id.begin(), p.id.end());
  std::vector<std::size_t> owned_slots;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!mine[k]) continue;
    owned_slots.push_back(k);
    for (std::size_t j = 0; j < all.size(); ++j)
      if (norm2(all.x[j] - p.x[k]) <= radius * radius) {
        ASSERT_TRUE(here.count(all.id[j]))
            << "rank " << w.rank() << ": id " << all.id[j] << " near id " << p.id[k];
      }
  }
  EXPECT_EQ(owned_slots.size(), owned);
  // The sums over the rows: the single-process bits for every owned particle.
  NeighborSearch<3, double> local, whole;
  NeighborList local_rows, whole_rows;
  local.build(std::span<const Vec<3, double>>(p.x), radius);
  local.find_all(local_rows);
  whole.build(std::span<const Vec<3, double>>(all.x), radius);
  whole.find_all(whole_rows);
  std::vector<std::size_t> same_ids;
  for (const std::size_t k : owned_slots) same_ids.push_back(p.id[k]);  // ids are the whole set's indices
  const auto here_rho = densities(p, local_rows, owned_slots, false);
  const auto want = densities(all, whole_rows, same_ids, false);
  const auto backwards = densities(all, whole_rows, same_ids, true);
  ASSERT_EQ(here_rho.size(), want.size());
  ASSERT_EQ(backwards.size(), want.size());
  std::size_t differ = 0;
  for (std::size_t t = 0; t < want.size(); ++t) {
    EXPECT_EQ(std::memcmp(&here_rho[t], &want[t], sizeof(double)), 0) << "id " << same_ids[t];
    differ += here_rho[t] != backwards[t] ? 1 : 0;
  }
  // A field written for the owned particles reaches every halo copy: the densities, refreshed.
  std::vector<double> rho(p.size(), -1.0);
  for (std::size_t t = 0; t < owned_slots.size(); ++t) rho[owned_slots[t]] = here_rho[t];
  refresh_halo(rho, plan, w);
  const auto every = densities(
      all, whole_rows,
      [&] {
        std::vector<std::size_t> ids(p.size());
        for (std::size_t k = 0; k < p.size(); ++k) ids[k] = p.id[k];
        return ids;
      }(),
      false);
  for (std::size_t k = 0; k < p.size(); ++k)
    EXPECT_EQ(std::memcmp(&rho[k], &every[k], sizeof(double)), 0)
        << "rank " << w.rank() << ", id " << p.id[k];
  // The order matters: summed backwards, some of these densities have other bits (the test could fail).
  std::int64_t counts[2] = {static_cast<std::int64_t>(differ), static_cast<std::int64_t>(want.size())};
  w.sum_in_place(counts, 2);
  EXPECT_GT(counts[0], 0);
  EXPECT_EQ(counts[1], static_cast<std::int64_t>(all.size()));
}

}  // namespace
}  // namespace cellsph::distributed
