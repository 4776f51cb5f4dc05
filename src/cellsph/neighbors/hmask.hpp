#pragma once
// The H-mask (paper section 4.1, fig. 1d): the set of cell offsets a particle in a home cell must
// search when cells have size h' = h / H.
//
// The paper's eq. 16 keeps offsets whose *centre offset length* |(h's, h't, h'u)| is below h. That
// drops cells that can still hold neighbours (for H = 2 the face cell (2,0,0) and the edge cell
// (2,2,0)); docs/neighbor-search.md measures how many pairs it misses. We keep every cell whose
// nearest point lies within h of the home cell instead, which never misses a neighbour.
//
// Exactness under rounding: cell coordinates are computed in double, and the grid is made a hair
// coarser than h / H (kCellInflation) so that a pair in cells whose gap is ruled out by the mask is
// farther apart than h by much more than the rounding of the |r_i - r_j| <= h_i test in float.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace cellsph {

// Cells are (h / H) * kCellInflation wide.
inline constexpr double kCellInflation = 1.0 + 1.0 / 65536.0;

// Cell sizes of the grid methods are kept in [kMinCellSize<Real>, kMaxCellSize]: 1 / cell stays finite
// and non-zero, and below kMinCellSize (about 1e4 sqrt of the smallest normal Real) squared distances
// may underflow, so that pairs farther apart than h can pass the test distance2 <= h^2; every pair
// closer than one cell lies in the 3^Dim cells around its home cell, so such pairs stay candidates. A
// cell larger than h / H is always exact: masks are built from the size actually used.
template <class Real>
inline constexpr double kMinCellSize = sizeof(Real) == 4 ? 1e-15 : 1e-150;
inline constexpr double kMaxCellSize = 1e307;
// A mask cell is kept when its gap to the home cell is <= h * kMaskSlack.
inline constexpr double kMaskSlack = 1.0 + 1.0 / 1048576.0;

template <int Dim>
struct MaskCell {
  std::array<int, Dim> offset{};
  // Squared gap between the home cell and this cell, in units of the cell size:
  // sum_k max(0, |offset_k| - 1)^2.
  int gap2 = 0;
};

template <int Dim>
inline int mask_gap2(const std::array<int, Dim>& o) {
  int g = 0;
  for (int k = 0; k < Dim; ++k) {
    const int a = std::max(0, std::abs(o[k]) - 1);
    g += a * a;
  }
  return g;
}

// Largest offset along one axis that can be needed for support `reach` (in cell units).
inline int mask_radius(double reach) {
  return static_cast<int>(std::floor(reach * kMaskSlack)) + 1;
}

// True when a cell with squared gap `gap2` (cell units) may hold a neighbour within `reach` cells.
inline bool mask_keeps(int gap2, double reach) {
  const double r = reach * kMaskSlack;
  return static_cast<double>(gap2) <= r * r;
}

// Every cell whose nearest point lies within `reach` cell sizes of the home cell, ordered like the
// Cell Indexing keys (axis 0 fastest, last axis slowest), so a traversal can stream through it.
template <int Dim>
std::vector<MaskCell<Dim>> h_mask(double reach) {
  const int R = mask_radius(reach);
  std::vector<MaskCell<Dim>> out;
  std::array<int, Dim> o{};
  o.fill(-R);
  while (true) {
    const int g = mask_gap2<Dim>(o);
    if (mask_keeps(g, reach)) out.push_back({o, g});
    int k = 0;
    while (k < Dim && ++o[k] > R) o[k++] = -R;
    if (k == Dim) break;
  }
  return out;
}

// The paper's eq. 16 taken literally, with h' = h / H: offsets s in [-H, H]^Dim with |s| h' < h,
// i.e. |s| < H. Kept only to measure what it misses; never used for searching.
template <int Dim>
std::vector<MaskCell<Dim>> h_mask_eq16(int H) {
  std::vector<MaskCell<Dim>> out;
  std::array<int, Dim> o{};
  o.fill(-H);
  while (true) {
    int len2 = 0;
    for (int k = 0; k < Dim; ++k) len2 += o[k] * o[k];
    if (len2 < H * H) out.push_back({o, mask_gap2<Dim>(o)});
    int k = 0;
    while (k < Dim && ++o[k] > H) o[k++] = -H;
    if (k == Dim) break;
  }
  return out;
}

}  // namespace cellsph
