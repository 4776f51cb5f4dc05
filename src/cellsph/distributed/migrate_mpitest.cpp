// Particles move to the ranks the curve's cuts give them, every field intact, in id order (issue 49 item
// 2). The whole set is made from a seed on every rank; what each rank must hold after the move is worked
// out from that whole set in one process (each particle's key, the cuts over all keys, its owner), not by
// the code under test.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "cellsph/distributed/communicator.hpp"
#include "cellsph/distributed/curve_split.hpp"
#include "cellsph/distributed/migrate.hpp"
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
      const std::size_t k = mine.size();
      mine.resize(k + 1);
      mine.for_each_field([&](std::string_view name, auto& field) {
        all.for_each_field([&](std::string_view n2, const auto& f2) {
          if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::decay_t<decltype(f2)>>)
            if (name == n2) field[k] = f2[i];
        });
      });
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

}  // namespace
}  // namespace cellsph::distributed
