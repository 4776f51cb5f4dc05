#pragma once
// The particle order of neighbors.reorder_every: a set of slots' particles sorted into Z-order of cells of
// size h (counted from the lowest corner of those particles), equal cells by id, so that the pair loops
// read neighbours close in memory. The order is a function of positions and ids alone (a total order, so
// any sort gives it), which keeps results independent of the neighbour method, the skin and the thread
// count. Particles move only among the given slots, so every slot keeps its kind.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// Z-order (Morton) key of a cell: the bits of the cell coordinates interleaved, so that cells close in
// space are mostly close in the key and each block of 2^Dim, 4^Dim, ... cells is contiguous.
// Bit b of the low 64 / Dim bits of v moved to bit Dim * b (the others 0): the usual shift-and-mask
// spreading, a few operations instead of a loop over the bits.
template <int Dim>
constexpr std::uint64_t spread_bits(std::uint64_t v) {
  if constexpr (Dim == 2) {
    v &= 0xffffffffULL;
    v = (v | (v << 16)) & 0x0000ffff0000ffffULL;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffULL;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0fULL;
    v = (v | (v << 2)) & 0x3333333333333333ULL;
    v = (v | (v << 1)) & 0x5555555555555555ULL;
  } else {
    static_assert(Dim == 3, "morton keys of 2 or 3 coordinates");
    v &= 0x1fffffULL;
    v = (v | (v << 32)) & 0x1f00000000ffffULL;
    v = (v | (v << 16)) & 0x1f0000ff0000ffULL;
    v = (v | (v << 8)) & 0x100f00f00f00f00fULL;
    v = (v | (v << 4)) & 0x10c30c30c30c30c3ULL;
    v = (v | (v << 2)) & 0x1249249249249249ULL;
  }
  return v;
}

template <int Dim>
std::uint64_t morton_key(const std::uint64_t (&c)[Dim]) {
  std::uint64_t key = 0;
  for (int a = 0; a < Dim; ++a) key |= spread_bits<Dim>(c[a]) << a;
  return key;
}

// from[k]: the slot whose particle slot slots[k] receives (slots ascending, at least one).
template <int Dim, class Real>
std::vector<std::uint32_t> cell_order(const std::vector<Vec<Dim, Real>>& x,
                                      const std::vector<std::uint32_t>& id, const IndexSet& slots,
                                      Real cell) {
  const std::size_t m = slots.size();
  Vec<Dim, Real> lo = x[slots[0]];
  for (const std::uint32_t i : slots)
    for (int a = 0; a < Dim; ++a) lo[a] = std::min(lo[a], x[i][a]);
  const Real inv = Real(1) / cell;
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
      // Finite positions (the stability check) at or above lo; far cells are clamped (only the order
      // suffers).
      const Real q = std::min(std::floor((x[i][a] - lo[a]) * inv), static_cast<Real>(cmax));
      c[a] = std::min(static_cast<std::uint64_t>(q), cmax);
    }
    items[k] = {morton_key<Dim>(c), id[i], i};
  });
  std::sort(items.begin(), items.end(),
            [](const Item& a, const Item& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
  std::vector<std::uint32_t> from(m);
  for (std::size_t k = 0; k < m; ++k) from[k] = items[k].slot;
  return from;
}

// Slot slots[k] of `field` receives the entry of slot from[k]. A field of another size than n is scratch
// not in use and is left alone.
template <class Field>
void permute_slots(Field& field, const IndexSet& slots, const std::vector<std::uint32_t>& from,
                   std::size_t n) {
  if (field.size() != n) return;
  using T = typename Field::value_type;
  const std::size_t m = slots.size();
  std::vector<T> tmp(m);
  parallel_for(m, [&](std::size_t k) { tmp[k] = field[from[k]]; });
  parallel_for(m, [&](std::size_t k) { field[slots[k]] = tmp[k]; });
}

}  // namespace cellsph
