// /solver/eos/stiffness when a scene leaves it out (docs/scenes.md, "Derived settings"): the stiffness
// that gives the scene's densest fluid the speed of sound c = 10 sqrt(2 g H), with H the drop from the
// fluid's highest point to the lowest wall below it. sqrt(2 g H) is the speed of a fall from that height,
// the fastest flow gravity makes there, so the Mach number stays near 0.1 and the density within about
// 1% (Monaghan 1994; DualSPHysics derives its coefficient the same way). A fixed default cannot: 1000 Pa
// is a speed of sound of 2.6 m/s for water, slower than a 1 m column falls.
// And /time/dt_column for DFSPH and IISPH: 0.7 d / sqrt(g H) from the same H, the longest step at which a
// resting column H deep settles (docs/physics.md, "The step limit of a resting column": measured c0 =
// 0.70-0.79 at three depths and spacings), so a scene run at a finer spacing (or made deeper) does not keep
// a dt_max chosen for a coarser one.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "cellsph/core/format.hpp"
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

namespace {

bool stiffness_given(const nlohmann::json& j) {
  return j.contains(nlohmann::json::json_pointer("/solver/eos/stiffness"));
}

// The fluid's top and the lowest wall under it (a wall particle, the write-up's box, the tank of
// boundary.walls, an up-facing plane of the paper's), as heights along `up`; lowest = +inf without a wall.
struct FluidDrop {
  double top = -std::numeric_limits<double>::infinity();
  double lowest = std::numeric_limits<double>::infinity();
};

// The lowest point of the box [lo, hi] along `up`.
template <int Dim, class Real>
double box_floor(const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi, const std::array<double, 3>& up) {
  double floor = 0;
  for (int a = 0; a < Dim; ++a)
    floor += std::min(up[static_cast<std::size_t>(a)] * double(lo[a]),
                      up[static_cast<std::size_t>(a)] * double(hi[a]));
  return floor;
}

template <int Dim, class Real>
FluidDrop fluid_drop(const SolverConfig<Dim, Real>& cfg, const Particles<Dim, Real>& p,
                     const std::array<double, 3>& up) {
  const auto height = [&up](const Vec<Dim, Real>& x) {
    double h = 0;
    for (int a = 0; a < Dim; ++a) h += up[static_cast<std::size_t>(a)] * double(x[a]);
    return h;
  };
  FluidDrop d;
  if (cfg.box.enabled) d.lowest = box_floor(cfg.box.lo, cfg.box.hi, up);  // the write-up's box
  // The tank's floor: with volume-map walls the only sign of it (its wall particles, where it has them,
  // lie below it).
  if (cfg.guard.container) d.lowest = std::min(d.lowest, box_floor(cfg.guard.lo, cfg.guard.hi, up));
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double h = height(p.x[i]);
    if (p.kind[i] == std::uint8_t(ParticleKind::Boundary)) {
      d.lowest = std::min(d.lowest, h);
      continue;
    }
    d.top = std::max(d.top, h);
    // The paper's planes facing up (a floor, a slope): where the vertical through this particle meets it.
    for (const auto& pl : cfg.planes) {
      double n_up = 0, n_x = 0;
      for (int a = 0; a < Dim; ++a) {
        n_up += double(pl.normal[a]) * up[static_cast<std::size_t>(a)];
        n_x += double(pl.normal[a]) * double(p.x[i][a]);
      }
      if (n_up > 0.5) d.lowest = std::min(d.lowest, h - (n_x - double(pl.offset)) / n_up);
    }
  }
  return d;
}

// What both defaults start from: the gravity's size and the drop H from the fluid's top to the lowest wall
// under it, measured against gravity (not finite without fluid or without a wall under it).
struct GravityDrop {
  double g = 0, height = 0;
};

template <int Dim, class Real>
GravityDrop gravity_drop(const SolverConfig<Dim, Real>& cfg, const Particles<Dim, Real>& p) {
  double g = 0;
  for (int a = 0; a < Dim; ++a) g += double(cfg.gravity[a]) * double(cfg.gravity[a]);
  g = std::sqrt(g);
  std::array<double, 3> up{};
  for (int a = 0; a < Dim; ++a) up[static_cast<std::size_t>(a)] = g > 0 ? -double(cfg.gravity[a]) / g : 0;
  const FluidDrop drop = fluid_drop(cfg, p, up);
  return {g, drop.top - drop.lowest};
}

}  // namespace

template <int Dim, class Real>
std::optional<DerivedSetting> default_stiffness(const nlohmann::json& j, SolverConfig<Dim, Real>& cfg,
                                                const Particles<Dim, Real>& p) {
  if (stiffness_given(j) || implicit_pressure(cfg.model)) return std::nullopt;
  DerivedSetting d{"/solver/eos/stiffness", double(cfg.eos.stiffness), ""};
  const auto [g, height] = gravity_drop(cfg, p);
  double rho0 = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == std::uint8_t(ParticleKind::Fluid))
      rho0 = std::max(rho0, double(cfg.phases[static_cast<std::size_t>(p.phase[i])].rest_density));
  if (!(g > 0) || !(rho0 > 0) || !(height > 0) || !std::isfinite(height)) {
    d.why = std::string(!(g > 0)    ? "no gravity"
                        : rho0 <= 0 ? "no fluid at the start"
                                    : "no wall below the fluid") +
            " to derive it from: the fixed default; set /solver/eos/stiffness";
    return d;
  }
  const double c = 10 * std::sqrt(2 * g * height);
  cfg.eos.stiffness = cfg.eos.stiffness_for_sound_speed(static_cast<Real>(c), static_cast<Real>(rho0));
  d.value = double(cfg.eos.stiffness);
  d.why = "speed of sound c = 10 sqrt(2 g H) = " + format_number("%.3g", c) +
          " m/s, H = " + format_number("%.3g", height) + " m from the fluid's top to the lowest wall";
  return d;
}

template <int Dim, class Real>
std::optional<DerivedSetting> default_column_step(const nlohmann::json& j, double spacing,
                                                  SolverConfig<Dim, Real>& cfg,
                                                  const Particles<Dim, Real>& p) {
  if (!implicit_pressure(cfg.model) || cfg.time.mode != TimeStepping::Courant ||
      j.contains(nlohmann::json::json_pointer("/time/dt_column")))
    return std::nullopt;
  DerivedSetting d{"/time/dt_column", 0.0, ""};
  const auto [g, height] = gravity_drop(cfg, p);
  if (!(g > 0) || !(height > 0) || !std::isfinite(height)) {
    d.why = std::string(!(g > 0) ? "no gravity" : "no fluid with a wall below it") +
            " to derive it from: no bound beyond time.dt_max";
    return d;
  }
  cfg.time.dt_column = static_cast<Real>(0.7 * spacing / std::sqrt(g * height));
  d.value = double(cfg.time.dt_column);
  d.why = "0.7 d / sqrt(g H), the longest step a resting column H = " + format_number("%.3g", height) +
          " m deep holds at spacing d = " + format_number("%.3g", spacing) + " m" +
          (cfg.time.dt_column < cfg.time.dt_max ? "; shorter than time.dt_max" : "; time.dt_max is shorter");
  return d;
}

#define CELLSPH_SOUND_SPEED_INSTANTIATE(D, R)                                                                \
  template std::optional<DerivedSetting> default_stiffness<D, R>(const nlohmann::json&, SolverConfig<D, R>&, \
                                                                 const Particles<D, R>&);                    \
  template std::optional<DerivedSetting> default_column_step<D, R>(                                          \
      const nlohmann::json&, double, SolverConfig<D, R>&, const Particles<D, R>&);
CELLSPH_SOUND_SPEED_INSTANTIATE(2, float)
CELLSPH_SOUND_SPEED_INSTANTIATE(2, double)
CELLSPH_SOUND_SPEED_INSTANTIATE(3, float)
CELLSPH_SOUND_SPEED_INSTANTIATE(3, double)
#undef CELLSPH_SOUND_SPEED_INSTANTIATE

}  // namespace cellsph::scene_detail
