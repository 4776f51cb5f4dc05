#pragma once
// Common vocabulary of every neighbour-search method: options, statistics and CSR output.
//
// Neighbour relation (paper eq. 14, extended to per-particle support as in section 4.1):
//   j is a neighbour of i  <=>  j != i  and  |r_i - r_j| <= h_i.
// With per-particle h the relation is not symmetric.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/core/fresh_memory.hpp"

namespace cellsph {

enum class Method { AllPairs, SpatialHash, CellIndex, SortedGrid, KdTree };

inline constexpr Method kAllMethods[] = {Method::AllPairs, Method::SpatialHash, Method::CellIndex,
                                         Method::SortedGrid, Method::KdTree};

std::string_view method_name(Method m);
std::optional<Method> parse_method(std::string_view name);
std::string method_names_joined(std::string_view sep = "|");

struct SearchOptions {
  Method method = Method::CellIndex;
  // Subdivision factor H: cells of size h' = h / H, searched with the H-mask (paper 4.1).
  int subdivision = 1;
  // Spatial Hashing table size M (eq. 15); 0 picks a prime near 2 * number of particles.
  std::size_t hash_table_size = 0;
  // Cell Indexing only: false leaves each row in the search's own order (cell by cell, a
  // deterministic function of the positions) instead of ascending, which saves sorting every row.
  // Every other method, and every caller that compares lists across methods, keeps it true.
  bool sorted_rows = true;
  // Cell Indexing only: false leaves the row of every point whose support is 0 empty without searching
  // it (true: its exact duplicates, the points at distance 0, as every method lists them). The solver's
  // wall particles search with support 0 and no step reads their rows: in a 3D tank they are two thirds
  // of the particles, and their queries a fifth of the search.
  bool zero_support_rows = true;
};

struct SearchStats {
  double build_ms = 0;             // building the structure (sort, hash, tree)
  double query_ms = 0;             // finding all neighbours
  std::uint64_t pairs = 0;         // ordered pairs (i, j) found
  std::uint64_t candidates = 0;    // distance tests performed
  std::uint64_t memory_bytes = 0;  // bytes held by the structure and the output lists
};

// Compressed sparse rows: neighbours of i are indices[offsets[i] .. offsets[i+1]).
// Each row is sorted ascending, so the output does not depend on the method or thread count.
// Both arrays are FreshVectors: their resize() leaves new entries unwritten (every search writes each
// one), so a fresh list pays no one-thread zero fill before the search fills it.
struct NeighborList {
  FreshVector<std::uint64_t> offsets;  // n + 1 entries
  FreshVector<std::uint32_t> indices;

  [[nodiscard]] std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  [[nodiscard]] std::size_t count(std::size_t i) const { return offsets[i + 1] - offsets[i]; }
  [[nodiscard]] std::uint64_t pairs() const { return indices.size(); }
  [[nodiscard]] std::size_t memory_bytes() const {
    return offsets.capacity() * sizeof(std::uint64_t) + indices.capacity() * sizeof(std::uint32_t);
  }
  // Row i as a [begin, end) pointer range.
  [[nodiscard]] const std::uint32_t* begin(std::size_t i) const { return indices.data() + offsets[i]; }
  [[nodiscard]] const std::uint32_t* end(std::size_t i) const { return indices.data() + offsets[i + 1]; }
};

}  // namespace cellsph
