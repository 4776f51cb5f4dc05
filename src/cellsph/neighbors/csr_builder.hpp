#pragma once
// Builds canonical CSR neighbour lists from any method's pair visitor.
//
// Two passes over the visitor (count, then fill) so that the only memory held besides the final
// lists is one counter per particle: peak memory stays at the lists' own size. Rows are then
// sorted ascending, which makes the output independent of method and thread count.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

// Sorts a short row in place; insertion sort wins for the ~30-element rows of SPH.
inline void sort_row(std::uint32_t* b, std::uint32_t* e) {
  if (e - b > 64) {
    std::sort(b, e);
    return;
  }
  for (std::uint32_t* p = b + 1; p < e; ++p) {
    const std::uint32_t v = *p;
    std::uint32_t* q = p;
    while (q > b && *(q - 1) > v) {
      *q = *(q - 1);
      --q;
    }
    *q = v;
  }
}

// `search` must provide `template <class F> std::uint64_t for_each_pair(F&&) const`.
// Returns the number of distance tests over both passes divided by two (one traversal's worth).
template <class Search>
std::uint64_t build_csr(const Search& search, std::size_t n, NeighborList& out) {
  out.offsets.assign(n + 1, 0);
  std::uint64_t* counts = out.offsets.data() + 1;
  const std::uint64_t candidates =
      search.for_each_pair([counts](std::uint32_t i, std::uint32_t, auto) { ++counts[i]; });
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] += out.offsets[i];

  out.indices.clear();
  out.indices.shrink_to_fit();
  out.indices.resize(out.offsets[n]);
  // Fill using a per-row cursor; the cursor array reuses no extra list-sized memory.
  std::vector<std::uint64_t> cursor(out.offsets.begin(), out.offsets.end() - 1);
  std::uint32_t* idx = out.indices.data();
  std::uint64_t* cur = cursor.data();
  search.for_each_pair([idx, cur](std::uint32_t i, std::uint32_t j, auto) { idx[cur[i]++] = j; });

  parallel_for(n, [&](std::size_t i) { sort_row(idx + out.offsets[i], idx + out.offsets[i + 1]); });
  return candidates;
}

}  // namespace cellsph
