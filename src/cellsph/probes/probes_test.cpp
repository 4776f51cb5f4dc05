// Probes against analytic fields on a resting lattice block: a linear (hydrostatic) pressure, a
// uniform velocity, and the block's own height for the level.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cellsph/probes/probes.hpp"
#include "cellsph/solver/initial.hpp"

namespace cellsph {
namespace {

constexpr double kRho0 = 1000, kG = 9.81;

// A block [0, W] x [0, H] (x [0, W]) at spacing s, at rest density, with p = rho0 g (H - y) and a
// uniform velocity (0.3, -0.2, 0.1); a row of wall particles under it with absurd values that no
// probe may read.
template <int Dim>
Particles<Dim, double> block(double width, double height, double s) {
  using V = Vec<Dim, double>;
  Particles<Dim, double> p;
  V lo{}, hi{};
  for (int k = 0; k < Dim; ++k) hi[k] = width;
  hi[Dim - 1] = height;
  add_block<Dim, double>(p, lo, hi, s, 0, kRho0 * std::pow(s, Dim));
  const std::size_t fluid = p.size();
  V wlo = lo, whi = hi;
  wlo[Dim - 1] = -s;
  whi[Dim - 1] = 0;
  add_block<Dim, double>(p, wlo, whi, s, 0, kRho0 * std::pow(s, Dim));
  p.resize(p.size());
  for (std::size_t j = 0; j < p.size(); ++j) {
    const bool wall = j >= fluid;
    p.kind[j] = static_cast<std::uint8_t>(wall ? ParticleKind::Boundary : ParticleKind::Fluid);
    p.rho[j] = kRho0;
    p.p[j] = wall ? 1e9 : kRho0 * kG * (height - p.x[j][Dim - 1]);
    const double v[3] = {0.3, -0.2, 0.1};
    for (int k = 0; k < Dim; ++k) p.v[j][k] = wall ? 1e3 : v[k];
  }
  return p;
}

template <int Dim>
void check_block() {
  const double s = 0.02, h = 2 * s, W = 0.4, H = 0.3;
  const auto p = block<Dim>(W, H, s);
  std::vector<Probe> probes;
  Probe mid{"mid", ProbeKind::Pressure, {W / 2, W / 2, W / 2}};
  mid.at[Dim - 1] = 0.1;
  Probe floor_sensor{"floor", ProbeKind::Pressure, {W / 2, W / 2, 0}};
  floor_sensor.at[Dim - 1] = s / 2;  // half a spacing above the wall
  Probe vel{"u", ProbeKind::Velocity, mid.at};
  Probe gauge{"gauge", ProbeKind::Level, {W / 2, W / 2, 0}};
  gauge.at[Dim - 1] = 0;  // its foot on the floor
  Probe dry{"dry", ProbeKind::Pressure, {W / 2, W / 2, 1.0}};
  dry.at[Dim - 1] = 1.0;
  Probe dry_gauge{"outside", ProbeKind::Level, {5.0, 5.0, 0}};
  dry_gauge.at[Dim - 1] = 0;
  probes = {mid, floor_sensor, vel, gauge, dry, dry_gauge};
  const auto cols = probe_columns(probes, Dim);
  ASSERT_EQ(cols.size(), 5U + Dim);
  EXPECT_EQ(cols[2], "u_x");
  EXPECT_EQ(cols[3], "u_y");
  for (KernelKind kernel : {KernelKind::CubicSpline, KernelKind::WendlandC2, KernelKind::Poly6}) {
    SCOPED_TRACE(static_cast<int>(kernel));
    const ProbeSampler<Dim, double> sampler(probes, kernel, h, s);
    const auto v = sampler.sample(p);
    ASSERT_EQ(v.size(), cols.size());
    // Interior: a linear field on a symmetric lattice is reproduced to rounding.
    EXPECT_NEAR(v[0], kRho0 * kG * (H - 0.1), 1e-6 * kRho0 * kG * H);
    // Half a spacing above the floor the kernel is cut by the wall: Shepard is first order there, off
    // by less than the pressure change over one spacing; never the walls' 1e9.
    EXPECT_NEAR(v[1], kRho0 * kG * (H - s / 2), kRho0 * kG * s);
    EXPECT_NEAR(v[2], 0.3, 1e-12);
    EXPECT_NEAR(v[3], -0.2, 1e-12);
    // The level: the block is H deep; phi crosses 1/2 within a fraction of a spacing of its top.
    EXPECT_NEAR(v[2 + Dim], H, 0.25 * s);
    EXPECT_TRUE(std::isnan(v[3 + Dim]));  // no fluid within h
    EXPECT_EQ(v[4 + Dim], 0.0);           // dry column
  }
}

TEST(Probes, PressureVelocityAndLevelOfARestingBlock2D) {
  check_block<2>();
}
TEST(Probes, PressureVelocityAndLevelOfARestingBlock3D) {
  check_block<3>();
}

// A gauge whose foot is above the floor measures the depth above its foot.
TEST(Probes, LevelIsMeasuredFromTheProbesFoot) {
  const double s = 0.02;
  const auto p = block<2>(0.4, 0.3, s);
  const ProbeSampler<2, double> sampler({{"g", ProbeKind::Level, {0.2, 0.1, 0}}}, KernelKind::CubicSpline,
                                        2 * s, s);
  EXPECT_NEAR(sampler.sample(p)[0], 0.2, 0.25 * s);
}

// Water in the air over a gauge (a block 0.1 m deep, and a blob 0.1 m thick from 0.3 to 0.4 m above a dry
// gap, as a plunging jet passes over a gauge): `level` reads the blob's top, `layer` the water standing
// on the floor; both read the same over the block alone, and a blob over a dry floor is dry for `layer`.
TEST(Probes, LayerIgnoresWaterAboveADryGap) {
  const double s = 0.02;
  Particles<2, double> p;
  add_block<2, double>(p, {{0, 0}}, {{0.4, 0.1}}, s, 0, kRho0 * s * s);
  add_block<2, double>(p, {{0, 0.3}}, {{0.2, 0.4}}, s, 0, kRho0 * s * s);
  for (std::size_t j = 0; j < p.size(); ++j) p.rho[j] = kRho0;
  const ProbeSampler<2, double> sampler({{"level", ProbeKind::Level, {0.1, 0, 0}},
                                         {"layer", ProbeKind::Layer, {0.1, 0, 0}},
                                         {"level_clear", ProbeKind::Level, {0.3, 0, 0}},
                                         {"layer_clear", ProbeKind::Layer, {0.3, 0, 0}}},
                                        KernelKind::CubicSpline, 2 * s, s);
  const auto v = sampler.sample(p);
  EXPECT_NEAR(v[0], 0.4, 0.25 * s);
  EXPECT_NEAR(v[1], 0.1, 0.25 * s);
  EXPECT_NEAR(v[2], 0.1, 0.25 * s);
  EXPECT_NEAR(v[3], v[2], 1e-3 * s);
  Particles<2, double> blob;  // the blob alone, over a dry floor
  add_block<2, double>(blob, {{0, 0.3}}, {{0.2, 0.4}}, s, 0, kRho0 * s * s);
  for (std::size_t j = 0; j < blob.size(); ++j) blob.rho[j] = kRho0;
  const auto d = sampler.sample(blob);
  EXPECT_NEAR(d[0], 0.4, 0.25 * s);
  EXPECT_EQ(d[1], 0.0);
}

TEST(Probes, KindNames) {
  for (ProbeKind k : {ProbeKind::Pressure, ProbeKind::Level, ProbeKind::Velocity, ProbeKind::Layer})
    EXPECT_EQ(parse_probe_kind(probe_kind_name(k)), k);
  EXPECT_FALSE(parse_probe_kind("height"));
}

}  // namespace
}  // namespace cellsph
