#pragma once
// PLACEHOLDER: to be replaced by the real implementation of CellIndex.
#include <cstdint>
#include <span>
#include <stdexcept>

#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

template <int Dim, class Real>
class CellIndex {
 public:
  explicit CellIndex(const SearchOptions& /*opt*/ = {}) {}
  void build(std::span<const Vec<Dim, Real>>, std::span<const Real>) {
    throw std::logic_error("CellIndex is not implemented yet");
  }
  template <class F>
  std::uint64_t for_each_pair(F&&) const { return 0; }
  [[nodiscard]] std::size_t memory_bytes() const { return 0; }
};

}  // namespace cellsph
