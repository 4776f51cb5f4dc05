#pragma once
// Shared by the solver tests only.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include <gtest/gtest.h>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/initial.hpp"
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

// Expects `base` edited by `edit` to fail validate() with an InputError whose message holds `mention` (the
// key and the value it names).
template <int Dim, class Real, class Edit>
void expect_edit_invalid(const SolverConfig<Dim, Real>& base, Edit edit, const std::string& mention) {
  SolverConfig<Dim, Real> cfg = base;
  edit(cfg);
  try {
    cfg.validate();
    ADD_FAILURE() << mention << ": no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
  }
}

// Water at spacing s: cubic spline, h = 2 s, Akinci walls, Courant steps at most dt_max.
template <int Dim, class Real>
SolverConfig<Dim, Real> dfsph_water(Real s, Real mu, Real dt_max) {
  SolverConfig<Dim, Real> cfg;
  cfg.model = Model::Dfsph;
  cfg.search.method = Method::CellIndex;
  cfg.density_kernel = KernelKind::CubicSpline;
  cfg.pressure_kernel = KernelKind::CubicSpline;
  cfg.support = 2 * s;
  cfg.phases[0].rest_density = 1000;
  cfg.phases[0].mass = Real(1000 * std::pow(double(s), Dim));
  cfg.phases[0].viscosity = mu;
  cfg.time.mode = TimeStepping::Courant;
  cfg.time.courant = Real(0.4);
  cfg.time.dt_max = dt_max;
  cfg.no_slip = true;
  return cfg;
}

// The DFSPH and IISPH tests' 2D dam break (solver/dfsph_test.cpp, iisph_test.cpp), the built-in scenes'
// coarsened: a 0.5 x 1 m column in a closed 2 x 1.2 m tank of Akinci walls, dfsph_water at 0.025 m with
// mu = 0.05 Pa s and steps of at most 5 ms, the search `method`.
struct DfsphDamBreak {
  SolverConfig<2, double> cfg;
  Particles<2, double> particles;
  static constexpr double s = 0.025, L = 2.0, Ht = 1.2;
};
inline DfsphDamBreak dfsph_dam_break(Method method) {
  using V2 = Vec<2, double>;
  DfsphDamBreak d;
  d.cfg = dfsph_water<2, double>(DfsphDamBreak::s, 0.05, 0.005);
  d.cfg.search.method = method;
  d.cfg.domain_set = true;
  d.cfg.domain_lo = V2{{-0.5, -0.5}};
  d.cfg.domain_hi = V2{{DfsphDamBreak::L + 0.5, DfsphDamBreak::Ht + 0.5}};
  add_block<2, double>(d.particles, V2{{0, 0}}, V2{{0.5, 1.0}}, DfsphDamBreak::s, 0);
  add_box_walls<2, double>(d.particles, V2{{0, 0}}, V2{{DfsphDamBreak::L, DfsphDamBreak::Ht}},
                           DfsphDamBreak::s, 2, false, 0, 0.0);
  return d;
}

// The small resting column of the DFSPH and IISPH tests: water 0.3 m wide and deep at 0.05 m in an open tank
// 0.4 m high of two layers of wall particles.
template <int Dim, class Real>
Particles<Dim, Real> small_column() {
  using V = Vec<Dim, Real>;
  V lo{}, hi{}, top{};
  for (int a = 0; a < Dim; ++a) {
    hi[a] = Real(0.3);
    top[a] = Real(0.3);
  }
  top[Dim - 1] = Real(0.4);
  Particles<Dim, Real> p;
  add_block<Dim, Real>(p, lo, hi, Real(0.05), 0);
  add_box_walls<Dim, Real>(p, lo, top, Real(0.05), 2, true, 0, Real(0));
  return p;
}

// The largest particle speed.
template <int Dim, class Real>
double max_speed(const Particles<Dim, Real>& p) {
  double vmax = 0;
  for (std::size_t i = 0; i < p.size(); ++i) vmax = std::max(vmax, double(norm(p.v[i])));
  return vmax;
}

inline const char* dfsph_wall_pressure_name(DfsphWallPressure w) {
  return w == DfsphWallPressure::Hydrostatic ? "hydrostatic"
         : w == DfsphWallPressure::Mirrored  ? "mirrored"
                                             : "zero";
}

// The resting column of the DFSPH step-limit checks (solver/dfsph_test.cpp, tools/dfsph_column.cpp): water
// `width` wide (in every horizontal direction) and `depth` deep at spacing s in an open tank of two layers
// of wall particles weighted like the fluid (rho0 s^Dim, so the lattice starts at rest density),
// dfsph_water with viscosity mu, steps of at most dt_max, support h = `support` s (2 unless a case says
// otherwise), walls whose pressure is `walls`. Gravity is along the last axis.
template <int Dim = 2>
struct DfsphColumn {
  using V = Vec<Dim, double>;
  double s = 0.02, width = 0.4, depth = 0.4, support = 2, mu = 5, dt_max = 0.005;
  DfsphWallPressure walls = DfsphWallPressure::Hydrostatic;
  bool volume_map = false;  // the tank as a volume map (boundary/bender2019.hpp), not wall particles
  static constexpr double rho0 = 1000, g = 9.81;
  // The WCSPH Courant step of the same resolution and support, 0.3 h / c with c = 10 sqrt(2 g depth) (the
  // dam-break scenes' sound speed and Courant number): what the "20x the WCSPH step" measures by.
  [[nodiscard]] double wcsph_step() const { return 0.3 * support * s / (10 * std::sqrt(2 * g * depth)); }
  [[nodiscard]] SolverConfig<Dim, double> config() const {
    auto cfg = dfsph_water<Dim, double>(s, mu, dt_max);
    cfg.support = support * s;
    cfg.dfsph.wall_pressure = walls;
    cfg.domain_set = true;
    cfg.domain_lo = corner(-0.1, -0.1);
    cfg.domain_hi = corner(width + 0.1, 2 * depth);
    if (volume_map) {
      cfg.wall_model = WallModel::VolumeMap;
      cfg.guard.container = true;
      cfg.guard.lo = corner(0, 0);
      cfg.guard.hi = corner(width, depth + 2 * s);
      cfg.guard.open_axis = Dim - 1;
      cfg.guard.depth = 0.5 * s;  // the scenes' (scene_readers.hpp, kGuardDepth)
    }
    return cfg;
  }
  [[nodiscard]] Particles<Dim, double> particles() const {
    Particles<Dim, double> p;
    add_block<Dim, double>(p, corner(0, 0), corner(width, depth), s, 0);
    double weight = rho0;
    for (int a = 0; a < Dim; ++a) weight *= s;
    if (!volume_map)
      add_box_walls<Dim, double>(p, corner(0, 0), corner(width, depth + 2 * s), s, 2, true, 0, weight);
    return p;
  }
  // The solver's pressure against rho0 g d, summed over the bottom row and over the lower half above it.
  struct PressureSums {
    double p_mid = 0, ref_mid = 0, p_bot = 0, ref_bot = 0;
    [[nodiscard]] double mid() const { return p_mid / ref_mid; }
    [[nodiscard]] double bottom() const { return p_bot / ref_bot; }
  };
  void add_pressures(const Particles<Dim, double>& q, PressureSums& sums) const {
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      const double y = q.x[i][Dim - 1], ref = rho0 * g * (depth - y);
      if (y < s) {
        sums.p_bot += q.p[i];
        sums.ref_bot += ref;
      } else if (y < depth / 2) {
        sums.p_mid += q.p[i];
        sums.ref_mid += ref;
      }
    }
  }
  // The point at `horizontal` along every axis but the last, `vertical` along the last.
  static V corner(double horizontal, double vertical) {
    V c{};
    for (int a = 0; a + 1 < Dim; ++a) c[a] = horizontal;
    c[Dim - 1] = vertical;
    return c;
  }
};

// 2D WCSPH water as the dam-break scenes set it up: cubic kernels, h = 2 spacings, ratio EOS with sound
// speed c, clamped negative pressure, the artificial viscosity mu = rho0 alpha h c / (2 (d + 2)) with
// alpha = 0.02, Courant steps.
inline SolverConfig<2, double> wcsph_water(double s, double c) {
  const double rho0 = 1000;
  SolverConfig<2, double> cfg;
  cfg.model = Model::Wcsph;
  cfg.search.method = Method::CellIndex;
  cfg.density_kernel = KernelKind::CubicSpline;
  cfg.pressure_kernel = KernelKind::CubicSpline;
  cfg.support = 2 * s;
  cfg.phases[0].rest_density = rho0;
  cfg.phases[0].mass = rho0 * s * s;
  cfg.phases[0].viscosity = rho0 * 0.02 * cfg.support * c / (2 * (2 + 2));
  cfg.eos.kind = EosKind::Ratio;
  cfg.eos.stiffness = rho0 * c * c;
  cfg.eos.clamp_negative = true;
  cfg.time.mode = TimeStepping::Courant;
  cfg.time.dt_max = 1e-3;
  return cfg;
}

// The weakly viscous box (issue 3's wall-energy problem; WallModels.WeaklyViscousBoxHoldsTenThousandSteps and
// tools/wall_energy_bookkeeping.cpp): water of viscosity mu filling a closed 0.5 m box of two layers of
// volume-weighted wall particles to 0.4 m, spacing 0.025 m, wcsph_water with c = 10 sqrt(2 g L). The fluid
// particles come first (fluid_count of them).
struct ViscousBox {
  static constexpr double s = 0.025, L = 0.5, H = 0.4, rho0 = 1000, g = 9.81;
  SolverConfig<2, double> cfg;
  Particles<2, double> particles;
  std::size_t fluid_count = 0;
};

inline ViscousBox weakly_viscous_box(Model model, WallModel walls, double mu) {
  using V2 = Vec<2, double>;
  using B = ViscousBox;
  ViscousBox box;
  box.cfg = wcsph_water(B::s, 10 * std::sqrt(2 * B::g * B::L));
  box.cfg.model = model;
  box.cfg.wall_model = walls;
  box.cfg.phases[0].viscosity = mu;
  box.cfg.domain_set = true;
  box.cfg.domain_lo = V2{{-0.2, -0.2}};
  box.cfg.domain_hi = V2{{B::L + 0.2, B::L + 0.2}};
  add_block<2, double>(box.particles, V2{{0, 0}}, V2{{B::L, B::H}}, B::s, 0);
  box.fluid_count = box.particles.size();
  add_box_walls<2, double>(box.particles, V2{{0, 0}}, V2{{B::L, B::L}}, B::s, 2, false, 0,
                           B::rho0 * B::s * B::s);
  return box;
}

}  // namespace cellsph::test
