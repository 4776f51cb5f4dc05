// A shaped solid's signed distance on a grid, for the solid guard (solver/boundary/solid_guard.hpp).
#include <cmath>

#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

template <int Dim, class Real>
void add_guard_grid(const geometry::Shape& shape, double spacing, bool container, GuardMover mover,
                    SolidGuard<Dim, Real>& guard) {
  // Distances are exact within a band of three spacings (clamped beyond): the guard acts from half a
  // spacing deep and trusts the gradient to two spacings deep (SolidGuardPass::keep_out_of_grid); a
  // particle deeper than that got there in one step and goes back to where it started it. A wider band
  // costs more at load: every node within it asks the mesh for its nearest triangle.
  const double band = kGuardGridBand * spacing, pitch = spacing;
  GuardGrid<Dim, Real> g;
  geometry::P3 origin{0, 0, 0};
  std::array<long, 3> n{1, 1, 1};
  for (int a = 0; a < Dim; ++a) {
    const auto k = static_cast<std::size_t>(a);
    origin[k] = shape.lo()[k] - band;
    n[k] = static_cast<long>(std::ceil((shape.hi()[k] - shape.lo()[k] + 2 * band) / pitch)) + 1;
    g.origin[a] = static_cast<Real>(origin[k]);
    g.n[a] = static_cast<std::int32_t>(n[k]);
  }
  g.pitch = static_cast<Real>(pitch);
  g.band = static_cast<Real>(band);
  g.first = guard.grid_values.size();
  g.container = container;
  g.mover = mover;
  for (const double d : geometry::signed_distance_grid(shape, origin, pitch, n, band))
    guard.grid_values.push_back(static_cast<Real>(container ? -d : d));
  guard.grids.push_back(g);
}

#define CELLSPH_GUARD_GRID_INSTANTIATE(D, R) \
  template void add_guard_grid<D, R>(const geometry::Shape&, double, bool, GuardMover, SolidGuard<D, R>&);
CELLSPH_GUARD_GRID_INSTANTIATE(2, float)
CELLSPH_GUARD_GRID_INSTANTIATE(2, double)
CELLSPH_GUARD_GRID_INSTANTIATE(3, float)
CELLSPH_GUARD_GRID_INSTANTIATE(3, double)
#undef CELLSPH_GUARD_GRID_INSTANTIATE

}  // namespace cellsph::scene_detail
