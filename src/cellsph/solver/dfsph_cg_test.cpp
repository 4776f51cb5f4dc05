// DFSPH's conjugate-gradient density solve (models/dfsph_cg.hpp, `dfsph.density_solver: "cg"`): the deep
// column against the Jacobi sweeps and rho g d, a 2D dam break against the tank walls, the same bits for
// any thread count, on the host-emulated device and through a checkpoint, and its keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

using test::dfsph_water;
using V2 = Vec<2, double>;

SolverConfig<2, double> with_cg(SolverConfig<2, double> cfg, double warm_scale) {
  cfg.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
  cfg.dfsph.warm_start_scale = warm_scale;
  return cfg;
}

// The column of dfsph_test.cpp (0.4 x 0.4 m at 0.02 m, mu = 5 Pa s, an open tank of two layers of wall
// particles weighted rho0 s^2, hydrostatic wall pressure) at 8 ms steps, 18.6x the WCSPH Courant step of
// this resolution: settled for 1 s, then sampled for 1 s.
struct ColumnRun {
  double sweeps = 0, p_mid = 0, p_bot = 0, kinetic = 0, kinetic_bound = 0;
  std::uint64_t hits = 0;
};

ColumnRun column(const SolverConfig<2, double>& base) {
  const double s = 0.02, W = 0.4, H = 0.4, rho0 = 1000, g = 9.81;
  auto cfg = base;
  cfg.dfsph.wall_pressure = DfsphWallPressure::Hydrostatic;
  cfg.domain_set = true;
  cfg.domain_lo = V2{{-0.1, -0.1}};
  cfg.domain_hi = V2{{W + 0.1, 2 * H}};
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{W, H}}, s, 0);
  add_box_walls<2, double>(p, V2{{0, 0}}, V2{{W, H + 2 * s}}, s, 2, true, 0, rho0 * s * s);
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, p);
  sim.run_until(1.0);
  const auto settled = sim.dfsph_stats();
  double p_mid = 0, ref_mid = 0, p_bot = 0, ref_bot = 0;
  while (sim.time() < 2.0) {
    sim.step();
    const auto& st = sim.dfsph_stats();
    if (st.last_density_iterations < cfg.dfsph.max_iterations) {
      EXPECT_LE(st.last_density_error, 0.05) << "step " << sim.steps();
    }
    const auto& q = sim.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      const double y = q.x[i][1], depth = H - y;
      if (y < s) {
        p_bot += q.p[i];
        ref_bot += rho0 * g * depth;
      } else if (y < H / 2) {
        p_mid += q.p[i];
        ref_mid += rho0 * g * depth;
      }
    }
  }
  const auto& st = sim.dfsph_stats();
  ColumnRun r;
  r.sweeps = double(st.density_iterations - settled.density_iterations) / double(st.steps - settled.steps);
  r.hits = st.max_iteration_hits - settled.max_iteration_hits;
  r.p_mid = p_mid / ref_mid;
  r.p_bot = p_bot / ref_bot;
  r.kinetic = sim.kinetic_energy();
  r.kinetic_bound = 1e-3 * sim.total_mass() * g * H;
  return r;
}

// The deep column is where Jacobi is slow: the pressure reaches the bottom one row a sweep. CG, started
// from most of the last step's pressure, meets the same bound in less than half the iterations, stops at
// max_iterations less often, and gives the same hydrostatic pressure.
TEST(DfsphCg, DeepColumnInFewerIterationsThanJacobi) {
  const auto base = dfsph_water<2, double>(0.02, 5.0, 0.008);
  const ColumnRun jacobi = column(base);
  const ColumnRun cg = column(with_cg(base, 0.85));
  std::cout << "[dfsph cg column, 8 ms] iterations/step jacobi " << jacobi.sweeps << " cg " << cg.sweeps
            << "; max-iteration hits " << jacobi.hits << " / " << cg.hits << "; p(lower half)/rho g d "
            << jacobi.p_mid << " / " << cg.p_mid << "; p(bottom row)/rho g d " << jacobi.p_bot << " / "
            << cg.p_bot << "; kinetic " << jacobi.kinetic << " / " << cg.kinetic << " J (bound "
            << cg.kinetic_bound << ")\n";
  EXPECT_LT(cg.sweeps, 0.5 * jacobi.sweeps);
  EXPECT_LE(cg.hits, jacobi.hits);
  EXPECT_NEAR(cg.p_mid, 1.0, 0.05);
  EXPECT_NEAR(cg.p_bot, 1.0, 0.05);
  EXPECT_LT(cg.kinetic, cg.kinetic_bound) << "the column should settle";
}

// The 2D dam break of dfsph_test.cpp (a 0.5 x 1 m column in a closed 2 x 1.2 m tank at 0.025 m, CFL
// steps): no fluid particle leaves the tank through the impact, and every solve keeps to its rules.
struct DamBreak {
  SolverConfig<2, double> cfg;
  Particles<2, double> particles;
  static constexpr double s = 0.025, L = 2.0, Ht = 1.2;
};

DamBreak dam_break(double warm_scale) {
  DamBreak d;
  d.cfg = with_cg(dfsph_water<2, double>(DamBreak::s, 0.05, 0.005), warm_scale);
  d.cfg.domain_set = true;
  d.cfg.domain_lo = V2{{-0.5, -0.5}};
  d.cfg.domain_hi = V2{{DamBreak::L + 0.5, DamBreak::Ht + 0.5}};
  add_block<2, double>(d.particles, V2{{0, 0}}, V2{{0.5, 1.0}}, DamBreak::s, 0);
  add_box_walls<2, double>(d.particles, V2{{0, 0}}, V2{{DamBreak::L, DamBreak::Ht}}, DamBreak::s, 2, false, 0,
                           0.0);
  return d;
}

TEST(DfsphCg, DamBreakLosesNoParticleThroughTheWalls) {
  auto d = dam_break(0.85);
  Simulation<2, double> sim(d.cfg, d.particles);
  double vmax = 0;
  while (sim.time() < 1.0) {
    sim.step();
    const auto& st = sim.dfsph_stats();
    ASSERT_GE(st.last_density_iterations, d.cfg.dfsph.min_iterations);
    ASSERT_LE(st.last_density_iterations, d.cfg.dfsph.max_iterations);
    if (st.last_density_iterations < d.cfg.dfsph.max_iterations) {
      ASSERT_LE(st.last_density_error, double(d.cfg.dfsph.max_density_error)) << "step " << sim.steps();
    }
    const auto& q = sim.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      vmax = std::max(vmax, norm(q.v[i]));
      ASSERT_TRUE(q.x[i][0] >= 0 && q.x[i][0] <= DamBreak::L && q.x[i][1] >= 0 && q.x[i][1] <= DamBreak::Ht)
          << "fluid particle " << i << " outside the tank after step " << sim.steps();
      ASSERT_GE(q.p[i], 0) << "a negative pressure (the solve clamps k at 0)";
    }
  }
  EXPECT_GT(vmax, 2.0) << "the front should have hit the far wall";
  const auto& st = sim.dfsph_stats();
  std::cout << "[dfsph cg dam break] steps " << sim.steps() << " density iterations/step "
            << double(st.density_iterations) / double(st.steps) << " max density error "
            << st.max_density_error << "% max-iteration hits " << st.max_iteration_hits << "\n";
}

// The same bits for one and two threads, on the host-emulated device (the CUDA backend's passes over host
// memory), and through a checkpoint (the warm start is p / rho^2 of the particle fields).
TEST(DfsphCg, BitIdenticalAcrossThreadsBackendsAndResume) {
  const auto d = dam_break(0.85);
  auto run = [&](int threads, Backend backend) {
    ScopedThreads t(threads);
    Simulation<2, double> sim(d.cfg, d.particles);
    sim.use_backend(backend);
    for (int k = 0; k < 40; ++k) sim.step();
    return sim.particles();
  };
  const auto a = run(2, Backend::Cpu);
  EXPECT_TRUE(test::same_state(a, run(1, Backend::Cpu))) << "one thread";
  EXPECT_TRUE(test::same_state(a, run(2, Backend::HostDevice))) << "host device";
  Simulation<2, double> first(d.cfg, d.particles);
  for (int k = 0; k < 20; ++k) first.step();
  Simulation<2, double> resumed(d.cfg, d.particles);
  resumed.restore(first.particles(), first.integrator_state(), "checkpoint", first.solver_state());
  for (int k = 20; k < 40; ++k) resumed.step();
  EXPECT_TRUE(test::same_state(resumed.particles(), a)) << "resumed";
  // And the solve is not the Jacobi sweeps under another name.
  auto jacobi = d.cfg;
  jacobi.dfsph.density_solver = DfsphDensitySolver::Jacobi;
  Simulation<2, double> j(jacobi, d.particles);
  for (int k = 0; k < 40; ++k) j.step();
  EXPECT_FALSE(test::same_state(a, j.particles()));
}

// Bad values name the key and the value; the scene keys are read and checked.
TEST(DfsphCg, SettingsAndSceneKeys) {
  auto expect_error = [](auto edit, const std::string& key) {
    auto cfg = dfsph_water<2, double>(0.02, 1.0, 0.01);
    edit(cfg);
    try {
      cfg.validate();
      ADD_FAILURE() << key << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  using C = SolverConfig<2, double>;
  expect_error([](C& c) { c.dfsph.warm_start_scale = 0; }, "dfsph.warm_start_scale = 0");
  expect_error([](C& c) { c.dfsph.warm_start_scale = 1.5; }, "dfsph.warm_start_scale = 1.5");
  expect_error(
      [](C& c) {
        c.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
        c.density = DensityFormulation::Number;
      },
      "dfsph.density_solver = cg");

  auto load = [](const std::string& dfsph) -> std::string {
    const std::string text = R"({"name": "t", "dimension": 2, "spacing": 0.05,
        "solver": {"model": "dfsph", "density_kernel": "cubic", "dfsph": )" +
                             dfsph + R"(},
        "fluids": [{"min": [0, 0], "max": [0.2, 0.2]}],
        "boundary": {"model": "akinci", "walls": {"min": [0, 0], "max": [0.4, 0.4], "layers": 2}}})";
    try {
      const auto sc = load_scene<2, double>(nlohmann::json::parse(text), "scene.json");
      EXPECT_EQ(sc.solver.dfsph.density_solver, DfsphDensitySolver::ConjugateGradient);
      EXPECT_EQ(sc.solver.dfsph.warm_start_scale, 0.85);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(load(R"({"density_solver": "cg", "warm_start_scale": 0.85})"), "");
  const std::string solver = load(R"({"density_solver": "gmres"})");
  EXPECT_NE(solver.find("/solver/dfsph/density_solver"), std::string::npos) << solver;
  EXPECT_NE(solver.find("gmres"), std::string::npos) << solver;
  const std::string scale = load(R"({"density_solver": "cg", "warm_start_scale": 2})");
  EXPECT_NE(scale.find("/solver/dfsph/warm_start_scale"), std::string::npos) << scale;
}

}  // namespace
}  // namespace cellsph
