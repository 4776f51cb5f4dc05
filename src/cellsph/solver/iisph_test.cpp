// IISPH (models/iisph.hpp): the hydrostatic column against rho g d at steps far past the WCSPH step, a 2D
// dam break at the CFL steps against the tank walls, the solve's stopping rule, bit-identity across runs,
// thread counts, neighbour methods, checkpoint/resume and the host-emulated device, and its scene keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/dfsph_test_checks.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

// Every step: at least min_iterations and at most max_iterations, and below the error bound unless it made
// the maximum; no divergence solve.
template <int Dim, class Real>
void expect_solve_rules(const Simulation<Dim, Real>& sim, const std::string& where) {
  const auto& st = sim.dfsph_stats();
  const auto& d = sim.config().dfsph;
  ASSERT_GE(st.last_density_iterations, d.min_iterations) << where;
  ASSERT_LE(st.last_density_iterations, d.max_iterations) << where;
  ASSERT_EQ(st.last_divergence_iterations, 0) << where;
  if (st.last_density_iterations < d.max_iterations) {
    ASSERT_LE(st.last_density_error, double(d.max_density_error)) << where;
  }
}

template <int Dim, class Real>
SolverConfig<Dim, Real> iisph(SolverConfig<Dim, Real> cfg) {
  cfg.model = Model::Iisph;
  return cfg;
}

// The resting column of the DFSPH tests (test::DfsphColumn: 0.4 x 0.4 m of water at 0.02 m, mu = 5 Pa s,
// hydrostatic walls) under IISPH at 5 ms steps, 11.6x the WCSPH step of the same resolution: settled for
// 1 s, then over the next second every step meets the bound (0.05%), and the solver's own pressure over the
// lower half within 2% of rho0 g d (the issue's criterion for DFSPH) and the bottom row within 5%
// (measured 1.016 and 1.026; DFSPH's sweeps 1.010 and 1.014: IISPH's stopping error is a signed average,
// SPlisHSPlasH's, where over- and under-compressed particles offset each other). It takes about 95
// iterations a step at these steps (ten times the dam break's): Jacobi at omega = 0.5 on a deep column.
TEST(Iisph, HydrostaticColumnFollowsRhoGDepth) {
  test::DfsphColumn<2> c;
  c.walls = DfsphWallPressure::Hydrostatic;
  c.dt_max = 0.005;
  ScopedThreads one(1);
  Simulation<2, double> sim(iisph(c.config()), c.particles());
  sim.run_until(1.0);
  const auto settled = sim.dfsph_stats();
  test::DfsphColumn<2>::PressureSums sums;
  double max_error = 0;
  while (sim.time() < 2.0) {
    sim.step();
    expect_solve_rules(sim, "step " + std::to_string(sim.steps()));
    max_error = std::max(max_error, sim.dfsph_stats().last_density_error);
    c.add_pressures(sim.particles(), sums);
  }
  const auto& st = sim.dfsph_stats();
  const double its =
      double(st.density_iterations - settled.density_iterations) / double(st.steps - settled.steps);
  std::cout << "[iisph hydrostatic] dt " << sim.last_dt() << " p(lower half)/rho g d " << sums.mid()
            << " p(bottom row)/rho g d " << sums.bottom() << " iterations/step " << its << " max error "
            << max_error << "% kinetic " << sim.kinetic_energy() << " J\n";
  EXPECT_EQ(sim.last_dt(), 0.005);
  EXPECT_EQ(st.max_iteration_hits, settled.max_iteration_hits) << "a solve stopped at max_iterations";
  EXPECT_NEAR(sums.mid(), 1.0, 0.02);
  EXPECT_NEAR(sums.bottom(), 1.0, 0.05);
  EXPECT_LT(sim.kinetic_energy(), 1e-3 * sim.total_mass() * c.g * c.depth) << "not settled";
}

// The DFSPH tests' coarse 2D dam break (test::DfsphDamBreak) under IISPH, with the walls' pressure `walls`.
using DamBreak = test::DfsphDamBreak;
DamBreak dam_break(Method method, DfsphWallPressure walls) {
  DamBreak d = test::dfsph_dam_break(method);
  d.cfg.model = Model::Iisph;
  d.cfg.dfsph.wall_pressure = walls;
  return d;
}

class IisphWalls : public ::testing::TestWithParam<int> {};  // 0 zero, 1 mirrored, 2 hydrostatic

// To t = 1 s: every solve keeps its rules, no fluid particle crosses the first layer of wall particles (half
// a spacing past the tank's faces; DFSPH's test asks the faces themselves, which IISPH's mirrored walls
// miss: one particle 0.008 spacings past the left face at t = 0.99 s), no pressure is negative (the clamp
// keeps k >= 0), and the front has hit the far wall at CFL steps below dt_max.
TEST_P(IisphWalls, DamBreakLosesNoParticleThroughTheWalls) {
  const auto d = dam_break(Method::CellIndex, static_cast<DfsphWallPressure>(GetParam()));
  Simulation<2, double> sim(d.cfg, d.particles);
  double dt_min = 1, vmax = 0, face = -1;  // face: the farthest any fluid particle got past a wall face
  while (sim.time() < 1.0) {
    sim.step();
    expect_solve_rules(sim, "step " + std::to_string(sim.steps()));
    dt_min = std::min(dt_min, sim.last_dt());
    const auto& q = sim.particles();
    std::size_t outside = 0, negative = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      vmax = std::max(vmax, norm(q.v[i]));
      const double m = DamBreak::s / 2;  // the first layer of wall particles
      if (q.x[i][0] < -m || q.x[i][0] > DamBreak::L + m || q.x[i][1] < -m || q.x[i][1] > DamBreak::Ht + m)
        ++outside;
      face = std::max({face, -q.x[i][0], q.x[i][0] - DamBreak::L, -q.x[i][1], q.x[i][1] - DamBreak::Ht});
      if (q.p[i] < 0) ++negative;
    }
    ASSERT_EQ(outside, 0u) << "fluid particles outside the tank after step " << sim.steps();
    ASSERT_EQ(negative, 0u) << "negative pressures after step " << sim.steps();
  }
  EXPECT_GT(vmax, 2.0);
  EXPECT_LT(dt_min, 0.005);
  const auto& st = sim.dfsph_stats();
  std::cout << "[iisph dam break] walls " << GetParam() << " steps " << sim.steps() << " iterations/step "
            << double(st.density_iterations) / double(st.steps) << " max error " << st.max_density_error
            << "% max-iteration hits " << st.max_iteration_hits << " farthest past a wall face "
            << face / DamBreak::s << " spacings\n";
}

// The host-emulated device (the CUDA backend's code path over host memory) gives the CPU's bits, and a run
// started there resumes on the CPU from its checkpoint state as if uninterrupted.
TEST_P(IisphWalls, HostDeviceIsBitIdenticalToTheCpuAndResumesAcrossBackends) {
  const auto d = dam_break(Method::CellIndex, static_cast<DfsphWallPressure>(GetParam()));
  test::expect_device_gives_the_cpus_run(d);
  test::expect_device_run_resumes_on_the_cpu(d);
}

INSTANTIATE_TEST_SUITE_P(Iisph, IisphWalls, ::testing::Values(0, 1, 2),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return i.param == 0 ? "Zero" : i.param == 1 ? "Mirrored" : "Hydrostatic";
                         });

// Same bits: two runs, one and two threads, two neighbour methods; and not DFSPH's.
TEST(Iisph, BitIdenticalAcrossRunsThreadsAndMethods) {
  auto run = [](Method method, int threads, Model model = Model::Iisph) {
    auto d = dam_break(method, DfsphWallPressure::Zero);
    d.cfg.model = model;
    ScopedThreads t(threads);
    Simulation<2, double> sim(d.cfg, d.particles);
    sim.run_until(0.3);
    return sim.particles();
  };
  const auto a = run(Method::CellIndex, 2);
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 2))) << "two runs";
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 1))) << "one thread";
  EXPECT_TRUE(test::same_state(a, run(Method::KdTree, 2))) << "kd-tree";
  EXPECT_FALSE(test::same_state(a, run(Method::CellIndex, 2, Model::Dfsph))) << "IISPH ran DFSPH's step";
}

// 3D float: a small column settles with every solve keeping its rules.
TEST(Iisph, SmallColumn3DFloat) {
  Simulation<3, float> sim(iisph(test::dfsph_water<3, float>(0.05f, 1.0f, 0.01f)),
                           test::small_column<3, float>());
  for (int k = 0; k < 40; ++k) {
    sim.step();
    expect_solve_rules(sim, "step " + std::to_string(k + 1));
  }
  EXPECT_LT(test::max_speed(sim.particles()), 0.5) << "a column at rest should stay nearly at rest";
}

// Bad settings name the key (as the scene spells it) and the value.
TEST(Iisph, BadSettingsAreInputErrors) {
  const auto base = iisph(test::dfsph_water<2, double>(0.02, 1.0, 0.01));
  auto expect_error = [&](auto edit, const std::string& key) { test::expect_edit_invalid(base, edit, key); };
  using C = SolverConfig<2, double>;
  expect_error([](C& c) { c.dfsph.max_density_error = 0; }, "iisph.max_density_error = 0");
  expect_error([](C& c) { c.dfsph.max_iterations = 0; }, "iisph.max_iterations = 0");
  expect_error([](C& c) { c.dfsph.relaxation = 0; }, "iisph.relaxation = 0");
  expect_error([](C& c) { c.dfsph.relaxation = 1.5; }, "iisph.relaxation = 1.5");
  expect_error([](C& c) { c.wall_model = WallModel::Adami; }, "boundary.model = adami");
  expect_error([](C& c) { c.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient; },
               "dfsph.density_solver = cg");
  auto ok = iisph(test::dfsph_water<2, double>(0.02, 1.0, 0.01));
  EXPECT_NO_THROW(ok.validate());
}

// The scene keys: /solver/iisph, read only for the IISPH model; unknown keys and bad values named with the
// file; /solver/dfsph refused under IISPH.
std::string scene_error(const std::string& model, const std::string& section, const std::string& body) {
  const std::string text = R"({"name": "t", "dimension": 2, "spacing": 0.05,
      "solver": {"model": ")" +
                           model + R"(", "density_kernel": "cubic", ")" + section + R"(": )" + body +
                           R"(},
      "fluids": [{"min": [0, 0], "max": [0.2, 0.2]}],
      "boundary": {"model": "akinci", "walls": {"min": [0, 0], "max": [0.4, 0.4], "layers": 2}}})";
  try {
    const auto sc = load_scene<2, double>(nlohmann::json::parse(text), "scene.json");
    EXPECT_EQ(sc.solver.model, Model::Iisph);
    EXPECT_EQ(sc.solver.verlet_skin, 0.0) << "the implicit models search at h every step";
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Iisph, SceneKeys) {
  EXPECT_EQ(scene_error("iisph", "iisph", R"({"max_density_error": 0.1, "min_iterations": 3,
      "max_iterations": 50, "warm_start": false, "warm_start_scale": 0.7, "relaxation": 0.6,
      "wall_pressure": "hydrostatic"})"),
            "");
  const std::pair<std::string, std::string> bad[] = {
      {R"({"max_density_error": 0})", "/solver/iisph/max_density_error"},
      {R"({"relaxation": 0})", "/solver/iisph/relaxation"},
      {R"({"relaxation": 1.2})", "/solver/iisph/relaxation"},
      {R"({"min_iterations": 9, "max_iterations": 4})", "/solver/iisph/min_iterations"},
      {R"({"max_divergence_error": 0.1})", "/solver/iisph/max_divergence_error"},
      {R"({"wall_pressure": "extrapolated"})", "/solver/iisph/wall_pressure"}};
  for (const auto& [value, key] : bad) {
    const std::string msg = scene_error("iisph", "iisph", value);
    EXPECT_NE(msg.find(key), std::string::npos) << value << " -> " << msg;
    EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  }
  EXPECT_NE(scene_error("dfsph", "iisph", "{}").find("/solver/iisph"), std::string::npos);
  const std::string switched = scene_error("iisph", "dfsph", "{}");
  EXPECT_NE(switched.find("/solver/dfsph"), std::string::npos) << switched;
  EXPECT_NE(switched.find("--set /solver/dfsph=null"), std::string::npos) << switched;
}

}  // namespace
}  // namespace cellsph
