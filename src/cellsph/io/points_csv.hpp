#pragma once
// Reading a point set from CSV, the input of `cellsph neighbors`.
//
// Format: a header row naming the columns `x,y` (2D) or `x,y,z` (3D) in any order, optionally `h`
// (per-particle support length), extra columns ignored. Every later row holds one particle.
// Parsing is strict: every needed field must be a finite number with nothing after it (surrounding
// spaces and CRLF line ends are tolerated), and `h` must be > 0. Any violation throws InputError
// with one line naming the file, the line (1-based, the header is line 1), the column and the value.
#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "cellsph/core/vec.hpp"

namespace cellsph {

struct PointsTable {
  int dim = 0;                               // 2 or 3
  std::array<std::vector<double>, 3> coord;  // coord[k][i]: axis k of particle i (k < dim)
  std::vector<double> h;                     // per-particle support; empty without an `h` column
  [[nodiscard]] std::size_t size() const { return coord[0].size(); }
  [[nodiscard]] bool has_h() const { return !h.empty(); }

  // The points as Vec<Dim, Real>; Dim must equal dim.
  template <int Dim, class Real>
  [[nodiscard]] std::vector<Vec<Dim, Real>> points() const {
    std::vector<Vec<Dim, Real>> x(size());
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int k = 0; k < Dim; ++k) x[i][k] = static_cast<Real>(coord[static_cast<std::size_t>(k)][i]);
    return x;
  }
};

// Parses CSV text; `source` names the file in error messages.
PointsTable parse_points_csv(std::string_view text, std::string_view source);

// Reads and parses a file (InputError when it cannot be read).
PointsTable read_points_csv(const std::filesystem::path& file);

}  // namespace cellsph
