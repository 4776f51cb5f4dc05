#pragma once
// Shared by the solver tests only.
#include <cstring>
#include <string_view>
#include <type_traits>

#include "cellsph/solver/particles.hpp"

namespace cellsph::test {

// True when every field of the field list holds the same bits in a and b (bit-identity checks:
// determinism across threads and methods, resume from a checkpoint).
template <int Dim, class Real>
bool same_state(const Particles<Dim, Real>& a, const Particles<Dim, Real>& b) {
  bool same = a.size() == b.size();
  a.for_each_field([&](std::string_view name, const auto& fa) {
    b.for_each_field([&](std::string_view nb, const auto& fb) {
      if constexpr (std::is_same_v<decltype(fa), decltype(fb)>) {
        if (name == nb)
          same = same && fa.size() == fb.size() &&
                 std::memcmp(fa.data(), fb.data(), fa.size() * sizeof(fa[0])) == 0;
      }
    });
  });
  return same;
}

}  // namespace cellsph::test
