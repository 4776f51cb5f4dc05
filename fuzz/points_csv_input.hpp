#pragma once
// libFuzzer harness: the points CSV reader of `cellsph neighbors` (io/points_csv). Bad input must end in
// InputError; anything else is a finding. A table that parses must hold what the reader promises.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "cellsph/io/points_csv.hpp"
#include "fuzz_util.hpp"

namespace cellsph::fuzz {

// One input of the harness (fuzz/points_csv_fuzz.cpp); also replayed by fuzz/regressions_test.cpp.
inline void points_csv_input(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const PointsTable t = parse_points_csv(text, "points.csv");
    // The promise of points_csv.hpp: 2 or 3 axes of equal length, finite values, h > 0 when given.
    if (t.dim != 2 && t.dim != 3) std::abort();
    for (int k = 0; k < t.dim; ++k) {
      const auto& c = t.coord[static_cast<std::size_t>(k)];
      if (c.size() != t.size()) std::abort();
      for (double v : c)
        if (!std::isfinite(v)) std::abort();
    }
    if (t.has_h()) {
      if (t.h.size() != t.size()) std::abort();
      for (double v : t.h)
        if (!(v > 0) || !std::isfinite(v)) std::abort();
    }
  } catch (const InputError&) {
  }
}

}  // namespace cellsph::fuzz
