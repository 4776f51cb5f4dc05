#include "cellsph/scene/inflow_reader.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace cellsph {

namespace {

// The value of `key` as the scene gives it.
std::string given(const JsonReader& e, const char* key) {
  return json_value_text(e.json()[key]);
}

void read_emitter(JsonReader& e, int dim, double spacing,
                  const std::function<std::int32_t(JsonReader&)>& phase_of, Emitter& em) {
  const auto d = static_cast<std::size_t>(dim);
  em.shape = e.choice("shape", "box", {"box", "disc"}) == "disc" ? EmitterShape::Disc : EmitterShape::Box;
  const auto c = e.required_vector("center", d);
  const auto n = e.required_vector("normal", d);
  double n2 = 0;
  for (std::size_t a = 0; a < d; ++a) {
    em.center[a] = c[a];
    em.normal[a] = n[a];
    n2 += n[a] * n[a];
  }
  if (!(n2 > 0)) e.fail("normal", given(e, "normal") + " has zero length (give the direction of the inflow)");
  // size: one number (2D, or a disc's diameter), or the two sides of a 3D box.
  const bool two = dim == 3 && em.shape == EmitterShape::Box;
  if (!e.has("size")) e.fail("size", "missing");
  std::vector<double> size;
  if (two)
    size = e.required_vector("size", 2);
  else
    size.push_back(e.required_number("size"));
  for (std::size_t k = 0; k < size.size(); ++k) {
    if (!(size[k] > 0)) e.fail("size", given(e, "size") + " must be > 0 (a length in m)");
    em.size[k] = size[k];
  }
  // One layer's particles (emitters.hpp: floor(size / spacing) along each tangent), bounded before any
  // is made: a layer of more than 10^7 is a typo, not an inlet.
  double cells = 1;
  for (std::size_t k = 0; k < (dim == 3 ? 2u : 1u); ++k)
    cells *= std::max(1.0, std::floor(size[two ? k : 0] / spacing * (1 + 1e-9)));
  if (cells > 1e7)
    e.fail("size", given(e, "size") + " makes layers of " + json_value_text(nlohmann::json(cells)) +
                       " particles at spacing " + json_value_text(nlohmann::json(spacing)) +
                       " (at most 10^7)");
  em.velocity = e.required_number("velocity");
  if (!(em.velocity >= 0))
    e.fail("velocity", given(e, "velocity") +
                           " must be >= 0 (the speed along the normal, m/s; turn the normal to reverse)");
  em.start = e.number("start", 0);
  em.end = e.number("end", HUGE_VAL);
  if (!(em.end >= em.start)) e.fail("end", given(e, "end") + " is before start " + given(e, "start"));
  em.depth = e.number("depth", 0);
  if (!(em.depth >= 0)) e.fail("depth", given(e, "depth") + " must be >= 0");
  em.phase = phase_of(e);
  e.finish();
}

void read_sink(JsonReader& e, int dim, Sink& s) {
  const auto d = static_cast<std::size_t>(dim);
  const auto lo = e.required_vector("min", d);
  const auto hi = e.required_vector("max", d);
  for (std::size_t a = 0; a < d; ++a) {
    if (!(hi[a] >= lo[a]))
      e.fail("max", given(e, "max") + " is below min " + given(e, "min") + " on axis " + std::to_string(a));
    s.lo[a] = lo[a];
    s.hi[a] = hi[a];
  }
  e.finish();
}

}  // namespace

void read_inflow(JsonReader& r, int dim, double spacing,
                 const std::function<std::int32_t(JsonReader&)>& phase_of, Inflow& out) {
  out.spacing = spacing;
  if (r.has("emitters")) {
    auto er = r.child("emitters");
    for (std::size_t k = 0; k < er.array_size(); ++k) {
      auto e = er.element(k);
      if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
      read_emitter(e, dim, spacing, phase_of, out.emitters.emplace_back());
    }
  }
  if (r.has("sinks")) {
    auto sr = r.child("sinks");
    for (std::size_t k = 0; k < sr.array_size(); ++k) {
      auto e = sr.element(k);
      if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
      read_sink(e, dim, out.sinks.emplace_back());
    }
  }
}

}  // namespace cellsph
