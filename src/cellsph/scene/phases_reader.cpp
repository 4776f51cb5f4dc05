// /phases (docs/scenes.md, "phases[k]"): the fluids and their parameters.
#include <cmath>

#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

std::int32_t PhaseTable::read_reference(JsonReader& e) const {
  if (!e.has("phase")) return 0;
  const auto& v = e.json()["phase"];
  if (v.is_string()) {
    const std::string name = e.string("phase", "");
    for (std::size_t k = 0; k < names.size(); ++k)
      if (names[k] == name) return static_cast<std::int32_t>(k);
    e.fail("phase", "no phase named \"" + name + "\"");
  }
  return static_cast<std::int32_t>(e.integer("phase", 0, 0, static_cast<long>(names.size()) - 1));
}

template <int Dim, class Real>
PhaseTable read_phases(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg) {
  PhaseTable t;
  if (!r.has("phases")) {
    cfg.phases[0].mass = cfg.phases[0].rest_density * static_cast<Real>(std::pow(spacing, Dim));
    t.names.push_back(cfg.phases[0].name);
    t.mass_given.push_back(false);
    t.mass.push_back(double(cfg.phases[0].mass));
    return t;
  }
  cfg.phases.clear();
  auto pr = r.child("phases");
  const std::size_t np = pr.array_size();
  if (np == 0) pr.fail_here("at least one phase is needed");
  for (std::size_t k = 0; k < np; ++k) {
    auto e = pr.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    Phase<Real> ph;
    ph.name = e.string("name", "phase" + std::to_string(k));
    ph.rest_density = static_cast<Real>(e.number("rest_density", 1000, 1e-6, 1e9));
    ph.mass = static_cast<Real>(e.number("mass", 0, 0, 1e12));
    ph.viscosity = static_cast<Real>(e.number("viscosity", 0, 0, 1e9));
    ph.color = static_cast<Real>(e.number("color", 1, -1e9, 1e9));
    ph.sigma = static_cast<Real>(e.number("sigma", 0, 0, 1e9));
    e.finish();
    t.mass_given.push_back(ph.mass != 0);
    if (ph.mass == 0) ph.mass = ph.rest_density * static_cast<Real>(std::pow(spacing, Dim));
    t.names.push_back(ph.name);
    t.mass.push_back(double(ph.mass));
    cfg.phases.push_back(ph);
  }
  return t;
}

#define CELLSPH_PHASES_INSTANTIATE(D, R) \
  template PhaseTable read_phases<D, R>(JsonReader&, double, SolverConfig<D, R>&);
CELLSPH_PHASES_INSTANTIATE(2, float)
CELLSPH_PHASES_INSTANTIATE(2, double)
CELLSPH_PHASES_INSTANTIATE(3, float)
CELLSPH_PHASES_INSTANTIATE(3, double)
#undef CELLSPH_PHASES_INSTANTIATE

}  // namespace cellsph::scene_detail
