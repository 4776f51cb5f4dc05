#pragma once
// Shared by the solver tests only.
#include <cstring>
#include <string_view>
#include <type_traits>

#include "cellsph/solver/config.hpp"
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

}  // namespace cellsph::test
