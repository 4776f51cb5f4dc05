// Equation-of-state values against the formulas, and the pair interactions' symmetries: a force that
// i feels from j is minus the one j feels from i (what conserves momentum), viscosity opposes relative
// motion, and interface tension vanishes below its threshold.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cellsph/physics/eos.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"

namespace cellsph {
namespace {

// density() inverts pressure(): hand-computed pairs (rho = 1100 or 1010 for rho0 = 1000), and the floor at
// rho0 / 2 for pressures below the state equation's value there.
TEST(Eos, DensityInvertsPressure) {
  EquationOfState<double> e;
  e.kind = EosKind::Tait;
  e.stiffness = 100;
  e.gamma = 7;
  EXPECT_NEAR(e.density(100 * (std::pow(1.1, 7) - 1), 1000), 1100, 1e-9);  // 1.1^7 = 1.9487171
  EXPECT_NEAR(e.density(94.87171, 1000), 1100, 1e-5);
  e.kind = EosKind::Ratio;
  e.stiffness = 2e4;
  EXPECT_NEAR(e.density(200, 1000), 1010, 1e-9);
  EXPECT_NEAR(e.density(-200, 1000), 990, 1e-9);
  e.clamp_negative = true;  // the inverse ignores the clamp: p = -200 still means 990
  EXPECT_NEAR(e.density(-200, 1000), 990, 1e-9);
  EXPECT_DOUBLE_EQ(e.density(-1e9, 1000), 500);
  e.kind = EosKind::Linear;
  e.stiffness = 2;
  EXPECT_NEAR(e.density(20, 1000), 1010, 1e-9);
  e.kind = EosKind::Seventh;
  e.stiffness = 100;
  EXPECT_NEAR(e.density(94.87171, 1000), 1100, 1e-5);
  EXPECT_DOUBLE_EQ(e.density(-100, 1000), 500);  // below the floor: (1/2)^7 - 1 = -0.992
}

TEST(Eos, FormsAndClamp) {
  EquationOfState<double> e;
  e.stiffness = 100;
  e.gamma = 7;
  e.kind = EosKind::Tait;
  EXPECT_NEAR(e.pressure(1010, 1000), 100 * (std::pow(1.01, 7) - 1), 1e-9);
  e.kind = EosKind::Seventh;
  EXPECT_NEAR(e.pressure(1010, 1000), 100 * (std::pow(1.01, 7) - 1), 1e-9);
  e.kind = EosKind::Linear;
  EXPECT_DOUBLE_EQ(e.pressure(1010, 1000), 1000);
  e.kind = EosKind::Ratio;
  EXPECT_NEAR(e.pressure(1010, 1000), 1, 1e-12);
  EXPECT_LT(e.pressure(990, 1000), 0);
  e.clamp_negative = true;
  EXPECT_EQ(e.pressure(990, 1000), 0);
  // c^2 = dp/drho at rest density, by a central difference.
  for (auto k : {EosKind::Tait, EosKind::Linear, EosKind::Ratio, EosKind::Seventh}) {
    e.kind = k;
    e.clamp_negative = false;
    const double dp = (e.pressure(1000.001, 1000) - e.pressure(999.999, 1000)) / 0.002;
    EXPECT_NEAR(e.sound_speed(1000), std::sqrt(dp), 1e-6 * std::sqrt(dp)) << eos_name(k);
    EXPECT_EQ(parse_eos(eos_name(k)), k);
  }
}

using V3d = Vec<3, double>;

PairInput<3, double> swap_ij(PairInput<3, double> in) {
  std::swap(in.mi, in.mj);
  std::swap(in.rhoi, in.rhoj);
  std::swap(in.pi, in.pj);
  std::swap(in.mui, in.muj);
  in.xij = -in.xij;
  in.vij = -in.vij;
  return in;
}

TEST(Interactions, PairForcesAreAntisymmetric) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const double h = 0.1;
  const SpikyKernel<3, double> spiky(h);
  const ViscosityKernel<3, double> visc(h);
  const CubicSplineKernel<3, double> cubic(h);
  for (int k = 0; k < 50; ++k) {
    PairInput<3, double> in{};
    in.xij = V3d{{u(gen), u(gen), u(gen)}} * 0.05;
    in.r = norm(in.xij);
    in.vij = V3d{{u(gen), u(gen), u(gen)}};
    in.mi = 1 + 0.5 * u(gen);
    in.mj = 1 + 0.5 * u(gen);
    in.rhoi = 1000 + 50 * u(gen);
    in.rhoj = 1000 + 50 * u(gen);
    in.pi = 100 * u(gen);
    in.pj = 100 * u(gen);
    in.mui = 1 + u(gen) / 2;
    in.muj = 1 + u(gen) / 2;
    const auto back = swap_ij(in);
    auto expect_opposite = [](const V3d& a, const V3d& b) {
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(a[d], -b[d], 1e-12 * (1 + std::abs(a[d])));
    };
    expect_opposite(averaged_pressure_force(in, spiky), averaged_pressure_force(back, spiky));
    expect_opposite(averaged_viscosity_force(in, visc), averaged_viscosity_force(back, visc));
    expect_opposite(symmetric_pressure_force(in, cubic), symmetric_pressure_force(back, cubic));
    expect_opposite(morris_viscosity_force(in, cubic, h / 2), morris_viscosity_force(back, cubic, h / 2));
    // Viscosity removes relative kinetic energy: the force on i opposes v_i - v_j (eq. 8b; Morris's acts
    // along v_ij).
    EXPECT_LE(dot(averaged_viscosity_force(in, visc), in.vij), 0);
    EXPECT_LE(dot(morris_viscosity_force(in, cubic, h / 2), in.vij), 1e-15);
  }
}

TEST(Interactions, PressurePushesApart) {
  const SpikyKernel<2, double> w(0.1);
  PairInput<2, double> in{};
  in.xij = Vec<2, double>{{0.03, 0}};
  in.r = 0.03;
  in.mi = in.mj = 1;
  in.rhoi = in.rhoj = 1000;
  in.pi = in.pj = 50;
  EXPECT_GT(averaged_pressure_force(in, w)[0], 0);
  EXPECT_GT(symmetric_pressure_force(in, w)[0], 0);
}

TEST(Interactions, TensionOnlyAboveThreshold) {
  ColorField<2, double> c;
  c.grad = Vec<2, double>{{3, 4}};
  c.lap = -2;
  EXPECT_EQ(norm2(interface_tension_force(c, 0.5, 6.0)), 0.0);
  const auto f = interface_tension_force(c, 0.5, 4.0);
  EXPECT_DOUBLE_EQ(f[0], 0.5 * 2 * 3 / 5);
  EXPECT_DOUBLE_EQ(f[1], 0.5 * 2 * 4 / 5);
}

}  // namespace
}  // namespace cellsph
