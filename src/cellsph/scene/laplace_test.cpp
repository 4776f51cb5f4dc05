// Laplace's law in 2D, two phases (issue 3): the built-in scene laplace-2d, a 0.2 m square of fluid
// "inside" (colour 1) in fluid "outside" (colour 0) filling a closed 0.5 m box of volume-weighted walls,
// equal rest densities (1000), sigma = 1 N/m for both, mu = 1 Pa s, no gravity, ratio EOS k = 1e4 Pa,
// cubic kernels, support 2 spacings. The square rounds into a disc of R = sqrt(area / pi) = 0.1128 m and
// the inside pressure exceeds the outside by sigma / R = 8.86 Pa (inside higher).
//
// Measured: R from the inside particle count; centre = their mean position; p_in = mean pressure of
// inside particles within R/2 of it, p_out = mean pressure of outside particles farther than R + support
// from it and more than one support from the walls; Delta p = p_in - p_out, averaged (weighted by dt)
// over t in [1, 2] s. Rounding: in eight 45-degree sectors (centred on the axes and diagonals) the
// outline radius max r + spacing/2 of the inside particles, against R (the square starts at 0.93 R on
// the axes and 1.23 R at the corners).
//
// The pressure that eq. 8a exerts is half the EOS pressure: -sum_j V_i V_j (p_i + p_j)/2 grad W_ij is
// -V_i grad p / 2 in a full neighbourhood (the p_i half sums to zero, PressureForceOfEq8aIsHalfTheGradient
// below). At equilibrium the mechanical jump (Delta p / 2) balances the tension, so the model's EOS jump
// is 2 sigma / R, and Delta p / 2 is what is compared with sigma / R.
//
// Resolution: spacing 0.0125 m (1600 fluid particles, 2000 steps per run, ~1 s in release); under
// ASan+UBSan (~10x slower) 0.025 m (400 particles, 6 s for the three runs). Convergence over 0.025 / 0.0125 /
// 0.00625 m: DISABLED_Convergence below, see docs/physics.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/physics/interactions.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr double kSpacing = 0.025;  // ASan+UBSan build: 4x fewer particles (see the header comment)
#else
constexpr double kSpacing = 0.0125;
#endif
constexpr auto kFluid = static_cast<std::uint8_t>(ParticleKind::Fluid);

struct Laplace {
  double radius = 0;                        // R = sqrt(area / pi) [m]
  double jump = 0;                          // EOS Delta p, time-averaged [Pa]
  double outline_min = 0, outline_max = 0;  // outline radius / R over the 8 sectors, at the end
  double drift = 0;                         // centre displacement at the end [m]
};

Laplace run_laplace(const std::string& tension, double sigma, double spacing) {
  std::string src;
  auto j = read_scene_json("laplace-2d", src);
  j["spacing"] = spacing;
  j["solver"]["support"] = 2 * spacing;
  j["solver"]["tension"] = tension;
  for (auto& ph : j["phases"]) ph["sigma"] = sigma;
  auto scene = load_scene<2, double>(j, src);
  ScopedThreads one(1);
  Simulation<2, double> sim(scene.solver, scene.particles);
  const auto& p = sim.particles();
  const double support = 2 * spacing, inner = 0.25 - support;  // the walls are at +-0.25 m
  auto inside = [&](std::size_t i) { return p.kind[i] == kFluid && p.phase[i] == 1; };
  std::size_t n_in = 0;
  for (std::size_t i = 0; i < p.size(); ++i) n_in += inside(i) ? 1 : 0;
  Laplace out;
  out.radius = std::sqrt(double(n_in) * spacing * spacing / M_PI);
  auto centre = [&] {
    double c[2] = {0, 0};
    for (std::size_t i = 0; i < p.size(); ++i)
      if (inside(i))
        for (int a = 0; a < 2; ++a) c[a] += p.x[i][a] / double(n_in);
    return std::vector<double>{c[0], c[1]};
  };
  double sum = 0, weight = 0;
  while (sim.time() < 2.0) {
    sim.step();
    if (sim.time() <= 1.0) continue;
    const auto c = centre();
    double s_in = 0, s_out = 0;
    int n_i = 0, n_o = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != kFluid) continue;
      const double r = std::hypot(p.x[i][0] - c[0], p.x[i][1] - c[1]);
      if (p.phase[i] == 1 && r < out.radius / 2) {
        s_in += p.p[i];
        ++n_i;
      } else if (p.phase[i] == 0 && r > out.radius + support && std::abs(p.x[i][0]) < inner &&
                 std::abs(p.x[i][1]) < inner) {
        s_out += p.p[i];
        ++n_o;
      }
    }
    sum += sim.last_dt() * (s_in / n_i - s_out / n_o);
    weight += sim.last_dt();
  }
  out.jump = sum / weight;
  const auto c = centre();
  out.drift = std::hypot(c[0], c[1]);
  std::vector<double> rmax(8, 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!inside(i)) continue;
    const double dx = p.x[i][0] - c[0], dy = p.x[i][1] - c[1];
    double a = std::atan2(dy, dx) + M_PI / 8;
    if (a < 0) a += 2 * M_PI;
    const auto k = std::min<std::size_t>(7, static_cast<std::size_t>(a / (M_PI / 4)));
    rmax[k] = std::max(rmax[k], std::hypot(dx, dy));
  }
  out.outline_min = (*std::min_element(rmax.begin(), rmax.end()) + spacing / 2) / out.radius;
  out.outline_max = (*std::max_element(rmax.begin(), rmax.end()) + spacing / 2) / out.radius;
  return out;
}

void print(const std::string& label, double spacing, double sigma, const Laplace& m) {
  const double ref = sigma / m.radius;
  std::cout << "[laplace] " << label << " spacing " << spacing << ": R = " << m.radius
            << " m, sigma/R = " << ref << " Pa; EOS jump " << m.jump << " Pa";
  if (sigma > 0)
    std::cout << " (" << m.jump / ref << " sigma/R), mechanical jump/2 error " << 100 * (m.jump / 2 / ref - 1)
              << "%";
  std::cout << "; outline " << m.outline_min << "-" << m.outline_max << " R, centre drift " << m.drift
            << " m\n";
}

// Eq. 8a's force on a particle in a full lattice neighbourhood with a linear pressure field p = g . x
// (unit spacing, m = rho = 1, so V = 1): half of -V_i grad p. Reference: int W = 1 gives
// sum_j V_j p_j grad W_ij -> grad p, while p_i sum_j V_j grad W_ij -> 0.
TEST(Laplace, PressureForceOfEq8aIsHalfTheGradient) {
  const CubicSplineKernel<2, double> w(2.0);
  const double g[2] = {3.0, -1.5};
  Vec<2, double> f{};
  for (int a = -3; a <= 3; ++a)
    for (int b = -3; b <= 3; ++b) {
      if (a == 0 && b == 0) continue;
      PairInput<2, double> in{};
      in.xij = Vec<2, double>{{-double(a), -double(b)}};
      in.r = std::hypot(a, b);
      in.mi = in.mj = in.rhoi = in.rhoj = 1;
      in.pi = 0;
      in.pj = g[0] * a + g[1] * b;
      f += averaged_pressure_force(in, w);
    }
  for (int a = 0; a < 2; ++a) EXPECT_NEAR(f[a] / -g[a], 0.5, 0.02) << a;  // measured 0.507 (lattice sum)
}

// Bounds, from the measurements at 0.025 / 0.0125 / 0.00625 m (docs/physics.md):
// - no tension: Delta p = 0 (the lattice stays at rest);
// - CSF: outline 0.997-1.009 R at 0.0125 m (1.004-1.025 at 0.025), asserted within 5%; mechanical jump
//   Delta p / 2 at +7%, +1.5%, -3% of sigma / R, asserted within 10%. Before its curvature sum was
//   normalised by the kernel sum of the neighbours that have a normal it was -7%, -16%, -17% (it took
//   n_j = n_i for neighbours farther than one support from the interface); this bound failed then.
// - eq. 9: Delta p = 2.0, 7.3, 10.6 sigma / R, growing with resolution, and the disc does not stay round
//   (outline 1.01-1.23 R, centre drift 5 cm at 0.0125 m): its direct lap C = sum_j V_j c_j lap W_ij
//   keeps c_i sum_j V_j lap W_ij (-2.9 / h^2 on the lattice for poly6, h = 2 spacings) inside a phase,
//   which pushes the colour-1 side inwards with ~sigma / h. Only the sign and a loose bound are asserted.
TEST(Laplace, TwoPhaseSquareRoundsWithPressureJumpSigmaOverR) {
  const double sigma = 1.0;
  const auto control = run_laplace("csf", 0, kSpacing);
  print("no tension", kSpacing, 0, control);
  const double ref = sigma / control.radius;
  EXPECT_NEAR(control.jump, 0, 0.01 * ref);
  // Without tension it stays a square (1.23 R at the corners, 1.21 R at 0.025 m): the measure sees corners.
  EXPECT_GT(control.outline_max, 1.15);

  const auto csf = run_laplace("csf", sigma, kSpacing);
  print("CSF", kSpacing, sigma, csf);
  EXPECT_GT(csf.outline_min, 0.95);
  EXPECT_LT(csf.outline_max, 1.05);
  EXPECT_NEAR(csf.jump / 2 / ref, 1.0, 0.10);

  const auto paper = run_laplace("paper", sigma, kSpacing);
  print("eq. 9", kSpacing, sigma, paper);
  EXPECT_GT(paper.jump, 0);  // inside at higher pressure
  EXPECT_LT(paper.jump, 20 * ref);
}

// The convergence study of docs/physics.md (30 s in release):
//   build/cellsph_tests --gtest_also_run_disabled_tests --gtest_filter='Laplace.DISABLED_Convergence'
TEST(Laplace, DISABLED_Convergence) {
  for (const double s : {0.025, 0.0125, 0.00625}) {
    print("no tension", s, 0, run_laplace("csf", 0, s));
    print("CSF", s, 1, run_laplace("csf", 1, s));
    print("eq. 9", s, 1, run_laplace("paper", 1, s));
  }
}

}  // namespace
}  // namespace cellsph
