// Initial particle layouts: box walls against their definition, site by site.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>
#include <tuple>

#include "cellsph/solver/initial.hpp"

namespace cellsph {
namespace {

// Every lattice site within `layers` of the box [0, n) along some axis and outside it, less the open
// top: the walls add_box_walls must make, enumerated over the whole (n + 2 layers)^Dim lattice.
template <int Dim>
std::set<std::array<int, 3>> wall_sites(const std::array<int, 3>& n, int layers, bool open_top, int up) {
  std::set<std::array<int, 3>> out;
  const int k0 = Dim == 3 ? -layers : 0, k1 = Dim == 3 ? n[2] + layers : 1;
  for (int k = k0; k < k1; ++k)
    for (int j = -layers; j < n[1] + layers; ++j)
      for (int i = -layers; i < n[0] + layers; ++i) {
        const std::array<int, 3> idx{i, j, k};
        bool outside = false;
        for (int a = 0; a < Dim; ++a) outside = outside || idx[a] < 0 || idx[a] >= n[a];
        if (outside && !(open_top && idx[up] >= n[up])) out.insert(idx);
      }
  return out;
}

template <int Dim>
void check_walls(const std::array<int, 3>& n, int layers, bool open_top, int up) {
  const double s = 0.1;
  Vec<Dim, double> lo, hi;
  for (int a = 0; a < Dim; ++a) {
    lo[a] = -0.3 * (a + 1);
    hi[a] = lo[a] + n[a] * s;
  }
  Particles<Dim, double> p;
  const std::size_t added = add_box_walls(p, lo, hi, s, layers, open_top, 0, 0.0, up);
  ASSERT_EQ(added, p.size());
  std::set<std::array<int, 3>> got;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::array<int, 3> idx{0, 0, 0};
    for (int a = 0; a < Dim; ++a) {
      const double c = (p.x[i][a] - lo[a]) / s - 0.5;
      idx[a] = static_cast<int>(std::lround(c));
      ASSERT_NEAR(c, idx[a], 1e-9) << "off the lattice";
    }
    EXPECT_TRUE(got.insert(idx).second) << "duplicate wall site";
  }
  EXPECT_EQ(got, wall_sites<Dim>(n, layers, open_top, up))
      << "n " << n[0] << "x" << n[1] << "x" << n[2] << ", layers " << layers << ", open top " << open_top;
}

TEST(BoxWalls, EverySiteAroundTheBoxOnceAndNoOther) {
  for (int layers : {1, 2, 3})
    for (bool open_top : {false, true}) {
      check_walls<2>({5, 3, 1}, layers, open_top, 1);
      check_walls<2>({1, 4, 1}, layers, open_top, 0);
      check_walls<3>({4, 3, 2}, layers, open_top, 2);
      check_walls<3>({2, 5, 3}, layers, open_top, 1);
    }
}

}  // namespace
}  // namespace cellsph
