// Every built-in scene, coarsened, over many steps (SceneStability), and at twice its spacing to its end
// (SceneAnySpacing, below). SceneStability: no NaN (the solver throws SimulationError), no fluid
// particle escaping its walls, and the energy of the fluid (kinetic + gravitational + the EOS's internal
// energy) never above its value after the first step by more than a small tolerance.
//
// Coarsening (test::scaled_scene): spacing, support, wall radius and explicitly given particle masses are
// scaled together (spacing * f, support * f, mass * f^dim), so each scene keeps its rest density,
// support/spacing ratio and every physics parameter (stiffness, viscosity, sigma, gravity, restitution,
// friction, time stepping); only the particle count drops (to ~180-430 fluid particles). The paper's dam
// breaks keep their support, Table 1's h (scaled_scene says why).
//
// Steps: issue 3's 10^4 per scene: 6.8-20 s of simulated time (the fixed-step scenes
// 20 s, the Courant-stepped 2D ones 6.8-9 s, dam-break-3d 16 s), well past each scene's whole dynamics
// (collapse, impact, return waves, settling; the Rayleigh-Taylor overturn). Each scene is its own ctest
// entry (value-parameterised), so `ctest -j2` runs them two at a time. Measured in CI's fresh clone (2
// cores, 20 scenes): release 6-9 s each for the six 3D ones below, 4 s for oil-glass, 0.7-3.2 s for the 2D
// ones; under ASan+UBSan at -O1 (scripts/test.sh) 8-40 s for those and 47-102 s for the six 3D ones (the
// paper's dam breaks, dam-break-3d and its DFSPH twin, spheric-test2), so scripts/test.sh runs those six in
// the release build only: their code runs under the sanitizers through the 3D solver tests and the 2D scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/builtin_scenes_test_util.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

constexpr int kSteps = 10000;  // issue 3: 10^4 steps of every scene, in every build (see the header)

// Fluid count the coarsening aims at: 400; 150 when the support is more than 3 spacings (h = 4.7 spacings
// gives ~400 neighbours each in 3D, ~13x the cost per particle of h = 2 spacings). The paper's dam breaks,
// the scenes with such a support, keep it when coarsened (test::scaled_scene): about 2 spacings at 150.
constexpr double kTargetParticles = 400, kTargetParticlesWide = 150;

nlohmann::json coarsened(nlohmann::json j) {
  const int dim = j.value("dimension", 2);
  double volume = 0;
  for (const auto& b : j["fluids"]) {
    double v = 1;
    if (b.contains("sphere")) {  // shaped fluid volumes (geometry/shape.hpp): the sphere's volume
      const double r = b["sphere"]["radius"].get<double>();
      v = dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
    } else {
      for (int a = 0; a < dim; ++a) v *= b["max"][a].get<double>() - b["min"][a].get<double>();
    }
    volume += v;
  }
  const double s = j["spacing"].get<double>();
  const double n = volume / std::pow(s, dim);
  const double ratio = j["solver"].value("support", 2 * s) / s;
  const double target = ratio > 3 ? kTargetParticlesWide : kTargetParticles;
  const double f = std::max(1.0, std::pow(n / target, 1.0 / dim));
  return test::scaled_scene(std::move(j), f);
}

// Internal (elastic) energy per unit mass of the equation of state, u(rho) = int_rho0^rho p(r) / r^2 dr,
// written out here for each kind (independently of physics/eos.hpp): it is >= 0, and zero below rho0 when
// negative pressures are clamped. A weakly compressible fluid stores energy in compression and, without
// the clamp, in tension: a lattice whose summed density is off rho0 releases it as motion, which is not an
// energy gain.
double internal_energy(const EquationOfState<double>& eos, double rho, double rho0) {
  if (eos.clamp_negative && rho < rho0) return 0;
  const double q = rho / rho0, k = eos.stiffness;
  switch (eos.kind) {
    case EosKind::Linear:  // p = k (rho - rho0)
      return k * (std::log(q) + 1 / q - 1);
    case EosKind::Ratio:  // p = k (rho / rho0 - 1)
      return k / rho0 * (std::log(q) + 1 / q - 1);
    case EosKind::Tait:
    case EosKind::Seventh: {  // p = k (q^gamma - 1)
      const double g = eos.kind == EosKind::Tait ? eos.gamma : 7.0;
      return k / ((g - 1) * rho0) * (std::pow(q, g - 1) - 1) + k * (1 / rho - 1 / rho0);
    }
  }
  return 0;
}

// Kinetic + gravitational potential + internal energy of the fluid particles.
template <int Dim, class Real>
double energy(const Simulation<Dim, Real>& sim) {
  const auto& p = sim.particles();
  const auto& cfg = sim.config();
  const auto g = cfg.gravity;
  EquationOfState<double> eos;
  eos.kind = cfg.eos.kind;
  eos.stiffness = double(cfg.eos.stiffness);
  eos.gamma = double(cfg.eos.gamma);
  eos.clamp_negative = cfg.eos.clamp_negative;
  double e = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != 0) continue;
    double v2 = 0, gx = 0;
    for (int a = 0; a < Dim; ++a) {
      v2 += double(p.v[i][a]) * double(p.v[i][a]);
      gx += double(g[a]) * double(p.x[i][a]);
    }
    const double rho0 = double(cfg.phases[static_cast<std::size_t>(p.phase[i])].rest_density);
    e += double(p.m[i]) * (0.5 * v2 - gx + internal_energy(eos, double(p.rho[i]), rho0));
  }
  return e;
}

// The up axis: the one gravity points against (its largest component; y without gravity). Every scene
// has y up except spheric-test2 (z up, as its data file).
template <int Dim, class Real>
int up_axis(const Simulation<Dim, Real>& sim) {
  int up = 1;
  for (int a = 0; a < Dim; ++a)
    if (std::abs(double(sim.config().gravity[a])) > std::abs(double(sim.config().gravity[up]))) up = a;
  return up;
}

// The region the fluid must stay in: the box, the walls (open top: no upper bound upwards), the planes.
template <int Dim, class Real>
void check_inside(const Simulation<Dim, Real>& sim, const nlohmann::json& j, const std::string& name,
                  int step) {
  const auto& p = sim.particles();
  const double tol = j["spacing"].get<double>();
  std::array<double, 3> lo{}, hi{};
  lo.fill(-std::numeric_limits<double>::infinity());
  hi.fill(std::numeric_limits<double>::infinity());
  const auto& b = j.contains("boundary") ? j["boundary"] : nlohmann::json::object();
  const bool walls = b.contains("walls");
  if (b.contains("box") || walls) {
    const auto& r = b.contains("box") ? b["box"] : b["walls"];
    for (int a = 0; a < Dim; ++a) {
      lo[a] = r["min"][a].get<double>();
      hi[a] = r["max"][a].get<double>();
    }
    if (walls && b["walls"].value("open_top", true)) hi[static_cast<std::size_t>(up_axis(sim))] = 1e300;
  } else if (j.contains("domain")) {  // free droplet: its domain
    for (int a = 0; a < Dim; ++a) {
      lo[a] = j["domain"]["min"][a].get<double>();
      hi[a] = j["domain"]["max"][a].get<double>();
    }
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != 0) continue;
    for (int a = 0; a < Dim; ++a)
      ASSERT_TRUE(double(p.x[i][a]) >= lo[a] - tol && double(p.x[i][a]) <= hi[a] + tol)
          << name << ": step " << step << ": particle " << i << " axis " << a << " at " << p.x[i][a];
    for (const auto& pl : sim.config().planes) {
      double d = -double(pl.offset);
      for (int a = 0; a < Dim; ++a) d += double(pl.normal[a]) * double(p.x[i][a]);
      ASSERT_GE(d, -tol) << name << ": step " << step << ": particle " << i << " behind a plane";
    }
  }
}

// energy_bound false: a scene with moving obstacles (dam-break-gate, wave-tank), whose walls do work on the
// fluid (the wave maker all the time), so its energy has no bound of this kind: it is checked for
// finiteness and containment only, and says so in its output line. (The same scenes with the motions
// removed are not a substitute: a 2 m column held by the still gate, and the still flume, both gain 10% of
// m g H within 1800-4000 steps at this resolution, the open wall-energy problem of Adami walls at water's
// viscosity, docs/physics.md.) Likewise a scene with emitters or sinks (channel-inflow): an open system,
// whose energy changes with the fluid that enters and leaves.
template <int Dim, class Real>
void run_scene(const nlohmann::json& j, const std::string& name, bool energy_bound = true) {
  // The source read_scene_json gives a built-in scene (its meshes/FILE are the compiled-in meshes).
  auto scene = load_scene<Dim, Real>(j, "built-in scene " + name);
  ScopedThreads one(1);
  Simulation<Dim, Real> sim(scene.solver, scene.particles);
  // Tolerance: 10% of the gravitational energy scale of the fluid (m g times the fluid's height), or,
  // without gravity, twice the interface energy sigma x perimeter the tension can turn into motion.
  // Not round-off: neither model's pressure force is the exact conjugate of its summed density (the
  // paper's averaged eq. 8a; the write-up's clamped pressure and mirrored walls), so the energy counted
  // with the EOS's internal energy sloshes by a few percent before viscosity takes it. Measured maximum
  // excess over 10^4 steps at this resolution, in % of m g H: dam-break-3d 6.0 (impact on the
  // obstacle), dam-break-2d 3.6, hydrostatic-tank 0.18, cuda-writeup 0.16, paper dam breaks and
  // two-phase 0 (energy only falls); droplet ~70% of its tolerance when it leaves its domain at step 8609
  // (eq. 9 does not conserve momentum: the drop propels itself; docs/physics.md). A blow-up gains far
  // more than this within a few steps (two-phase with its former wall particles: +11% of m g H in 200
  // steps, then out of the box).
  double g = 0, height = 0, mass = 0;
  for (int a = 0; a < Dim; ++a) g += double(scene.solver.gravity[a]) * double(scene.solver.gravity[a]);
  g = std::sqrt(g);
  double ylo = 1e300, yhi = -1e300;
  const int up = up_axis(sim);
  const auto& q = sim.particles();
  for (std::size_t i = 0; i < q.size(); ++i)
    if (q.kind[i] == 0) {
      ylo = std::min(ylo, double(q.x[i][up]));
      yhi = std::max(yhi, double(q.x[i][up]));
      mass += double(q.m[i]);
    }
  height = yhi - ylo + double(scene.spacing);
  double sigma = 0;
  for (const auto& ph : scene.solver.phases) sigma = std::max(sigma, double(ph.sigma));
  const double area = mass / double(scene.solver.phases[0].rest_density);
  const double perimeter = Dim == 2 ? 4 * std::sqrt(area) : 6 * std::pow(area, 2.0 / 3);
  const double tol = g > 0 ? 0.10 * mass * g * height : 2 * sigma * perimeter;

  // The reference is the energy after the first step: the solver starts every particle at rho0 and the
  // first step sums the real density (and with it the stored internal energy) of the initial lattice.
  sim.step();
  const double e0 = energy(sim);
  double emax = e0;
  for (int s = 1; s < kSteps; ++s) {
    try {
      sim.step();
    } catch (const SimulationError& e) {
      FAIL() << name << ": " << e.what();
    }
    const double e = energy(sim);
    emax = std::max(emax, e);
    if (energy_bound) {
      ASSERT_LE(e, e0 + tol) << name << ": step " << s << ": energy " << e << " > initial " << e0 << " + "
                             << tol;
    }
    if (s % 50 == 0 || s == kSteps - 1) {
      check_inside(sim, j, name, s);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  if (!energy_bound) {
    std::cout << "[stability] " << name
              << " (moving walls or inflow, energy not bounded: work done, fluid in and out): "
              << sim.fluid_count() << " fluid particles, " << kSteps << " steps to t = " << sim.time()
              << " s, energy " << e0 << " -> " << energy(sim) << "\n";
    return;
  }
  std::cout << "[stability] " << name << ": " << sim.fluid_count() << " fluid particles, " << kSteps
            << " steps to t = " << sim.time() << " s, energy " << e0 << " -> " << energy(sim)
            << " (max excess " << emax - e0 << " = " << 100 * (emax - e0) / tol << "% of the tolerance "
            << tol << ")\n";
}

class SceneStability : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneStability, CoarsenedStaysFiniteInsideAndEnergyBounded) {
  std::string src;
  const auto j = coarsened(read_scene_json(GetParam(), src));
  const auto h = read_scene_header(j, src);
  // Moving obstacles (boundary.obstacles[k].motion), emitters and sinks: no energy bound (see run_scene).
  bool moving = j.contains("emitters") || j.contains("sinks");
  if (j.contains("boundary") && j["boundary"].contains("obstacles"))
    for (const auto& o : j["boundary"]["obstacles"]) moving = moving || o.contains("motion");
  moving = moving || j.contains("bodies");  // floating bodies trade energy with the fluid
  // Double precision everywhere: float scenes are run in double here (the float path is compared with
  // double in the solver's tests); the physics is the same.
  if (h.dim == 2)
    run_scene<2, double>(j, GetParam(), !moving);
  else
    run_scene<3, double>(j, GetParam(), !moving);
}

INSTANTIATE_TEST_SUITE_P(Builtin, SceneStability, ::testing::ValuesIn(test::builtin_scene_names()),
                         test::scene_test_name);

// Issue 52 item 3, the coarse end: the scene at twice its spacing (test::scaled_scene), in its own
// precision, to its time.end: no instability, no fluid particle out of its tank (checked every 50 steps),
// and its walls hold by themselves (the solid guard put back at most 0.1% of the fluid per simulated
// second, the share above which `cellsph run` warns). The fine end (half the spacing) is measured once in
// docs/scenes.md, "Any spacing".
template <int Dim, class Real>
void run_to_the_end(const nlohmann::json& j, const std::string& src, const std::string& name) {
  auto scene = load_scene<Dim, Real>(j, src);
  Simulation<Dim, Real> sim(scene.solver, scene.particles);
  const double end = j["time"]["end"].get<double>();
  int step = 0;
  while (double(sim.time()) < end) {
    try {
      sim.step();
    } catch (const SimulationError& e) {
      FAIL() << name << ": " << e.what();
    }
    if (++step % 50 == 0) {
      check_inside(sim, j, name, step);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  check_inside(sim, j, name, step);
  const double share = double(sim.wall_corrections()) / double(sim.fluid_count()) / end;
  EXPECT_LE(share, 0.001) << name << ": " << sim.wall_corrections() << " fluid particles put back";
  std::cout << "[any spacing] " << name << " at twice its spacing: " << sim.fluid_count()
            << " fluid particles, " << step << " steps to t = " << sim.time() << " s, "
            << sim.wall_corrections() << " put back from walls\n";
}

class SceneAnySpacing : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneAnySpacing, TwiceTheSpacingRunsToTheEnd) {
  std::string src;
  const auto j = test::scaled_scene(read_scene_json(GetParam(), src), 2.0);
  const auto h = read_scene_header(j, src);
  if (h.dim == 2)
    h.single_precision ? run_to_the_end<2, float>(j, src, GetParam())
                       : run_to_the_end<2, double>(j, src, GetParam());
  else
    h.single_precision ? run_to_the_end<3, float>(j, src, GetParam())
                       : run_to_the_end<3, double>(j, src, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Builtin, SceneAnySpacing, ::testing::ValuesIn(test::builtin_scene_names()),
                         test::scene_test_name);

// The front (the 99th percentile of the fluid's x, nearest rank) and the mean height (y) of a 3D scene at
// time `end`.
std::pair<double, double> front_and_level(const nlohmann::json& j, const std::string& src, double end) {
  auto scene = load_scene<3, double>(j, src);
  ScopedThreads two(2);
  Simulation<3, double> sim(scene.solver, scene.particles);
  while (double(sim.time()) < end) sim.step();
  std::vector<double> x;
  double level = 0;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == 0) {
      x.push_back(p.x[i][0]);
      level += p.x[i][1];
    }
  std::sort(x.begin(), x.end());
  return {x[static_cast<std::size_t>(0.99 * double(x.size() - 1))], level / double(x.size())};
}

// Issue 52 item 3, the same physics at another spacing: the paper's three dam breaks at their own spacing
// (1600 particles) and at twice it (200, the support kept) have, after 1 s, the same front and mean height
// within one coarse spacing (measured: front 0.204 / 0.203 m, 0.200 / 0.196, 0.204 / 0.196; mean height
// 0.0142 / 0.0149, 0.0154 / 0.0159, 0.0153 / 0.0168). With the support doubled too, paper-dam-break-1's
// block collapsed into one layer (front 0.108 m, mean height 0.000; checked by hand).
TEST(SceneAnySpacingPhysics, PaperDamBreaksAtTwiceTheSpacingKeepTheirFrontAndLevel) {
  for (const char* name : {"paper-dam-break-1", "paper-dam-break-2", "paper-dam-break-3"}) {
    SCOPED_TRACE(name);
    std::string src;
    const auto base = read_scene_json(name, src);
    const auto [front1, level1] = front_and_level(base, src, 1.0);
    const auto coarse = test::scaled_scene(base, 2.0);
    const auto [front2, level2] = front_and_level(coarse, src, 1.0);
    const double d = coarse["spacing"].get<double>();
    EXPECT_NEAR(front2, front1, d);
    EXPECT_NEAR(level2, level1, d);
    std::cout << "[any spacing] " << name << ": front " << front1 << " / " << front2 << " m, mean height "
              << level1 << " / " << level2 << " m at 1 and 2 times its spacing\n";
  }
}

}  // namespace
}  // namespace cellsph
