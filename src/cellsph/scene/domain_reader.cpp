// /domain (docs/scenes.md, "Top level"): the box a particle must stay in, given or by default.
#include "cellsph/scene/scene_readers.hpp"

#include <algorithm>
#include <cmath>

namespace cellsph::scene_detail {

template <int Dim, class Real>
void read_domain(JsonReader& r, SolverConfig<Dim, Real>& cfg, Regions<Dim>& regions) {
  if (!r.has("domain")) return;
  auto dr = r.child("domain");
  const auto b = read_box<Dim>(dr);
  dr.finish();
  // Every shaped obstacle (with the walls a container puts outside it) must fit the domain.
  for (std::size_t k = 0; k < regions.all_shapes.size(); ++k) {
    const auto& s = regions.all_shapes[k];
    const double m = regions.shape_margins[k];
    for (std::size_t a = 0; a < Dim; ++a)
      if (s.lo()[a] - m < b.lo[a] || s.hi()[a] + m > b.hi[a])
        r.fail("domain", "does not hold the shape of " + regions.shape_keys[k] +
                             " (with its walls): on axis " + std::to_string(a) + " it spans " +
                             std::to_string(s.lo()[a] - m) + " to " + std::to_string(s.hi()[a] + m) +
                             ", the domain " + std::to_string(b.lo[a]) + " to " + std::to_string(b.hi[a]));
  }
  cfg.domain_set = true;
  cfg.domain_lo = to_vec<Dim, Real>(b.lo);
  cfg.domain_hi = to_vec<Dim, Real>(b.hi);
  if (!regions.container) regions.container = b;
}

// A scene without /domain and without a box: the bounding box of its starting particles and emitters,
// grown on every side by the box's longest side (at least 10 spacings). A particle beyond it has flown
// off (an explosion, a jet out of an open tank): the run stops and says so, instead of running on with a
// particle in free flight.
template <int Dim, class Real>
void default_domain(const Particles<Dim, Real>& p, const Inflow& inflow, double spacing,
                    SolverConfig<Dim, Real>& cfg) {
  if (cfg.domain_set || cfg.box.enabled) return;
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  auto grow = [&](int a, double x) {
    lo[a] = std::min(lo[a], x);
    hi[a] = std::max(hi[a], x);
  };
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < Dim; ++a) grow(a, double(p.x[i][a]));
  for (const Emitter& e : inflow.emitters)
    for (int a = 0; a < Dim; ++a) grow(a, e.center[a]);
  if (!(lo[0] <= hi[0])) return;  // nothing to bound
  double side = 10 * spacing;
  for (int a = 0; a < Dim; ++a) side = std::max(side, hi[a] - lo[a]);
  cfg.domain_set = true;
  cfg.domain_default = true;
  for (int a = 0; a < Dim; ++a) {
    cfg.domain_lo[a] = static_cast<Real>(lo[a] - side);
    cfg.domain_hi[a] = static_cast<Real>(hi[a] + side);
  }
}

#define CELLSPH_DOMAIN_INSTANTIATE(D, R)                                          \
  template void read_domain<D, R>(JsonReader&, SolverConfig<D, R>&, Regions<D>&); \
  template void default_domain<D, R>(const Particles<D, R>&, const Inflow&, double, SolverConfig<D, R>&);
CELLSPH_DOMAIN_INSTANTIATE(2, float)
CELLSPH_DOMAIN_INSTANTIATE(2, double)
CELLSPH_DOMAIN_INSTANTIATE(3, float)
CELLSPH_DOMAIN_INSTANTIATE(3, double)
#undef CELLSPH_DOMAIN_INSTANTIATE

}  // namespace cellsph::scene_detail
