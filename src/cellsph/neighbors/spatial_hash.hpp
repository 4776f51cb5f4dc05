#pragma once
// PLACEHOLDER: to be replaced by the real implementation of SpatialHash.
#include <cstdint>
#include <span>
#include <stdexcept>

#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

template <int Dim, class Real>
class SpatialHash {
 public:
  explicit SpatialHash(const SearchOptions& /*opt*/ = {}) {}
  void build(std::span<const Vec<Dim, Real>>, std::span<const Real>) {
    throw std::logic_error("SpatialHash is not implemented yet");
  }
  template <class F>
  std::uint64_t for_each_pair(F&&) const { return 0; }
  [[nodiscard]] std::size_t memory_bytes() const { return 0; }
};

}  // namespace cellsph
