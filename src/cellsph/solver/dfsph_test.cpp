// DFSPH (models/dfsph.hpp): the hydrostatic column against rho g d, a 2D dam break at the CFL steps
// against the tank walls, the solvers' stopping rule, bit-identity across runs, thread counts and
// neighbour methods, float and 3D, the conjugate-gradient density solve (models/dfsph_cg.hpp), and the
// validation of its keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/dfsph_test_checks.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/models/dfsph.hpp"
#include "cellsph/solver/pass_driver.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

using test::dfsph_water;

using V2 = Vec<2, double>;

// The checks every DFSPH step must pass: each solve made at least its minimum and at most its maximum
// number of sweeps, and stopped below its error bound unless it made the maximum.
template <int Dim, class Real>
void expect_solver_rules(const Simulation<Dim, Real>& sim, const std::string& where) {
  const auto& st = sim.dfsph_stats();
  const auto& d = sim.config().dfsph;
  ASSERT_GE(st.last_density_iterations, d.min_iterations) << where;
  ASSERT_LE(st.last_density_iterations, d.max_iterations) << where;
  ASSERT_GE(st.last_divergence_iterations, 1) << where;
  ASSERT_LE(st.last_divergence_iterations, d.max_iterations) << where;
  if (st.last_density_iterations < d.max_iterations) {
    ASSERT_LE(st.last_density_error, double(d.max_density_error)) << where;
  }
  if (st.last_divergence_iterations < d.max_iterations) {
    ASSERT_LE(st.last_divergence_error, double(d.max_divergence_error)) << where;
  }
}

// The column of test::DfsphColumn (0.4 x 0.4 m of water at spacing 0.02 m, mu = 5 Pa s unless a case says
// otherwise) at rest, stepped at dt_max after settling for 1 s; over the next second, the solver's pressure
// against rho0 g d summed over the lower half above the bottom row and over the bottom row, the largest
// density error, the solves stopped at max_iterations and the kinetic energy at the end. dt_max = 5 ms is
// 11.6x the WCSPH Courant step of the same resolution (0.3 h / (10 sqrt(2 g H)) = 0.43 ms at h = 2 s).
struct ColumnRun {
  double p_mid = 0, p_bot = 0, max_error = 0, kinetic = 0, kinetic_bound = 0;
  std::uint64_t hits = 0;
  double dt = 0;
  double sweeps = 0;  // density iterations a step after settling
};

test::DfsphColumn<2> column(DfsphWallPressure walls, double dt_max) {
  test::DfsphColumn<2> c;
  c.walls = walls;
  c.dt_max = dt_max;
  return c;
}

// `cg`: the conjugate-gradient density solve (models/dfsph_cg.hpp) from warm_scale of the last k.
ColumnRun settle_column(const test::DfsphColumn<2>& c, bool check_every_step, bool cg = false,
                        double warm_scale = 0.5) {
  auto cfg = c.config();
  if (cg) cfg.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
  cfg.dfsph.warm_start_scale = warm_scale;
  ScopedThreads one(1);  // 400 particles: thread start-up would dominate
  Simulation<2, double> sim(cfg, c.particles());
  sim.run_until(1.0);
  const auto settled = sim.dfsph_stats();
  const auto hits_settling = settled.max_iteration_hits;
  test::DfsphColumn<2>::PressureSums sums;
  ColumnRun r;
  while (sim.time() < 2.0) {
    sim.step();
    if (check_every_step) {
      expect_solver_rules(sim, "step " + std::to_string(sim.steps()));
      EXPECT_LE(sim.dfsph_stats().last_density_error, 0.05);
    }
    r.max_error = std::max(r.max_error, sim.dfsph_stats().last_density_error);
    c.add_pressures(sim.particles(), sums);
  }
  r.p_mid = sums.mid();
  r.p_bot = sums.bottom();
  r.hits = sim.dfsph_stats().max_iteration_hits - hits_settling;
  r.sweeps = double(sim.dfsph_stats().density_iterations - settled.density_iterations) /
             double(sim.dfsph_stats().steps - settled.steps);
  r.kinetic = sim.kinetic_energy();
  r.kinetic_bound = 1e-3 * sim.total_mass() * c.g * c.depth;
  r.dt = sim.last_dt();
  const auto& st = sim.dfsph_stats();
  std::cout << "[dfsph hydrostatic] " << (cg ? "cg" : "jacobi") << " walls "
            << test::dfsph_wall_pressure_name(c.walls) << " support " << c.support << " s, mu " << c.mu
            << " Pa s, steps " << sim.steps() << " dt " << r.dt << " p(lower half)/rho g d " << r.p_mid
            << " p(bottom row)/rho g d " << r.p_bot << " density sweeps/step "
            << double(st.density_iterations) / double(st.steps) << " divergence sweeps/step "
            << double(st.divergence_iterations) / double(st.steps) << " max density error " << r.max_error
            << "% kinetic " << r.kinetic << " J\n";
  return r;
}

// Walls at k = 0 (the default): every step meets the 0.05% bound and the lower half follows rho0 g d
// within 5%. The bottom row carries the column on the wall's k = 0 terms alone (Akinci's unmirrored
// pressure, as SPlisHSPlasH): its pressure is 1.5-2x rho0 g d (measured 1.77), checked as such.
TEST(Dfsph, HydrostaticColumnFollowsRhoGDepth) {
  const ColumnRun r = settle_column(column(DfsphWallPressure::Zero, 0.005), true);
  EXPECT_EQ(r.dt, 0.005) << "the column should be slow enough for dt_max";
  EXPECT_EQ(r.hits, 0u) << "a solve stopped at max_iterations";
  EXPECT_NEAR(r.p_mid, 1.0, 0.05);
  EXPECT_GE(r.p_bot, 1.5);
  EXPECT_LE(r.p_bot, 2.0);
  EXPECT_LT(r.kinetic, r.kinetic_bound) << "not settled";
}

// Mirrored walls (`wall_pressure: "mirrored"`): the same column, and the bottom row's pressure within
// 10% of rho0 g d (measured 1.06: the wall's pressure is the particle's own, a zeroth-order extrapolation
// of a field that grows downwards).
TEST(Dfsph, MirroredWallsCarryTheBottomRowAtRhoGDepth) {
  const ColumnRun r = settle_column(column(DfsphWallPressure::Mirrored, 0.005), true);
  EXPECT_EQ(r.dt, 0.005);
  EXPECT_EQ(r.hits, 0u) << "a solve stopped at max_iterations";
  EXPECT_NEAR(r.p_mid, 1.0, 0.05);
  EXPECT_NEAR(r.p_bot, 1.0, 0.10);
  EXPECT_LT(r.kinetic, r.kinetic_bound) << "not settled";
}

// Hydrostatic walls (`wall_pressure: "hydrostatic"`): the mirrored pressure plus rho_i g . (x_b - x_i)
// to each wall particle. The issue's 2%: the bottom row and the lower half within 2% of rho0 g d (measured
// 1.014 and 1.010 at 5 ms; 0.995 and 1.005 at 8 ms, where it settles too). At 8.7 ms (20.3x) it still
// sloshes (0.80x after 2 s, 19 solves at max_iterations; docs/physics.md).
TEST(Dfsph, HydrostaticWallsCarryTheBottomRowAtRhoGDepth) {
  const ColumnRun r = settle_column(column(DfsphWallPressure::Hydrostatic, 0.005), true);
  EXPECT_EQ(r.dt, 0.005);
  EXPECT_EQ(r.hits, 0u) << "a solve stopped at max_iterations";
  EXPECT_NEAR(r.p_mid, 1.0, 0.02);
  EXPECT_NEAR(r.p_bot, 1.0, 0.02);
  EXPECT_LT(r.kinetic, r.kinetic_bound) << "not settled";
  const ColumnRun longer = settle_column(column(DfsphWallPressure::Hydrostatic, 0.008), false);
  EXPECT_EQ(longer.dt, 0.008);
  EXPECT_LT(longer.kinetic, longer.kinetic_bound) << "not settled at 8 ms";
  EXPECT_NEAR(longer.p_mid, 1.0, 0.02);
  EXPECT_NEAR(longer.p_bot, 1.0, 0.02);
}

// Hydrostatic walls in a tank that moves: the column of HydrostaticColumnFollowsRhoGDepth (mu 5 Pa s, 5 ms
// steps) in a tank whose walls oscillate vertically, y_w = A sin(2 pi t / T) with A = 0.05 m and T = 0.5 s
// (acceleration up to 7.9 m/s^2, 0.8 g), the water started with the tank's velocity. In the tank's frame
// gravity is g - a_w, so the bottom row's pressure is rho0 |g - a_w| d, d its depth below the tank's water
// line H + y_w. Over t = 1-2 s (two periods), summed over the steps where the tank pushes up hardest (a_w
// above half its peak: effective gravity 1.4-1.8 g) and where it falls (0.2-0.6 g): the swing between the
// two, (P_up - P_fall) / (R_up - R_fall), within 2.5% of the reference's (measured 0.984), and each within
// 5% (measured 0.996 and 1.040: the bottom row's +1.4% of rho0 g d at rest is a larger part of the falling
// tank's smaller pressure). The swing needs a_w in the wall term: with g alone it measured 1.039, and
// mirrored walls 1.035. (At T = 1 s, A = 0.2 m both measured 0.99: the shaken column sloshes there.)
TEST(Dfsph, HydrostaticWallsFollowTheTanksAcceleration) {
  const double s = 0.02, W = 0.4, H = 0.4, rho0 = 1000, g = 9.81, A = 0.05, T = 0.5, w = 2 * M_PI / T;
  auto cfg = dfsph_water<2, double>(s, 5.0, 0.005);
  cfg.dfsph.wall_pressure = DfsphWallPressure::Hydrostatic;
  cfg.domain_set = true;
  cfg.domain_lo = V2{{-0.1, -0.2}};
  cfg.domain_hi = V2{{W + 0.1, 2 * H}};
  Particles<2, double> p;
  add_box_walls<2, double>(p, V2{{0, 0}}, V2{{W, H + 2 * s}}, s, 2, true, 0, rho0 * s * s);
  WallMotion m;
  m.kind = MotionKind::Oscillate;
  m.direction[0] = 0;
  m.direction[1] = 1;
  m.amplitude = A;
  m.period = T;
  cfg.wall_motion.motions.push_back(m);
  cfg.wall_motion.of_particle.assign(p.size(), 0);
  add_block<2, double>(p, V2{{0, 0}}, V2{{W, H}}, s, 0);
  cfg.wall_motion.of_particle.resize(p.size(), -1);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == 0) p.v[i] = V2{{0, A * w}};
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, p);
  sim.run_until(1.0);
  double up = 0, up_ref = 0, fall = 0, fall_ref = 0;
  while (sim.time() < 2.0) {
    sim.step();
    const double t = sim.time(), yw = A * std::sin(w * t), aw = -A * w * w * std::sin(w * t);
    if (std::abs(aw) < 0.5 * A * w * w) continue;
    const auto& q = sim.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0 || q.x[i][1] - yw >= s) continue;
      const double ref = rho0 * (g + aw) * (H + yw - q.x[i][1]);
      (aw > 0 ? up : fall) += q.p[i];
      (aw > 0 ? up_ref : fall_ref) += ref;
    }
  }
  const double swing = (up - fall) / (up_ref - fall_ref);
  std::cout << "[dfsph moving tank] bottom row p / rho0 |g - a_w| d: pushed up " << up / up_ref
            << ", falling " << fall / fall_ref << ", swing " << swing << "\n";
  EXPECT_NEAR(swing, 1.0, 0.025);
  EXPECT_NEAR(up / up_ref, 1.0, 0.05);
  EXPECT_NEAR(fall / fall_ref, 1.0, 0.05);
}

// At 8 ms (18.6x the WCSPH step) the column with mirrored walls still settles and keeps its bottom row
// (walls at k = 0 measured 1.8 J of motion against the 0.63 J bound there, their bottom row sliding on
// the floor). Some solves reach max_iterations at this step, so the per-step bound is not checked.
TEST(Dfsph, MirroredWallsSettleTheColumnAtLongerSteps) {
  const ColumnRun r = settle_column(column(DfsphWallPressure::Mirrored, 0.008), false);
  EXPECT_EQ(r.dt, 0.008);
  EXPECT_LT(r.kinetic, r.kinetic_bound) << "not settled";
  EXPECT_NEAR(r.p_mid, 1.0, 0.05);
  EXPECT_NEAR(r.p_bot, 1.0, 0.10);
  EXPECT_LT(r.max_error, 0.5) << "density error in percent";
}

// The 2D dam break of the built-in scenes, coarse (test::DfsphDamBreak). At the CFL steps (0.4 d / max |v|,
// at most 5 ms) no fluid particle leaves the tank, and every solve keeps to its rules.
using DamBreak = test::DfsphDamBreak;
DamBreak dam_break(Method method) {
  return test::dfsph_dam_break(method);
}

// Both wall pressures ("zero" and "mirrored").
class DfsphWalls : public ::testing::TestWithParam<int> {};  // 0 zero, 1 mirrored, 2 hydrostatic

// Runs the dam break to t = 1 s: every solve keeps to its rules, no fluid particle leaves the tank and
// none takes a negative pressure (both solves keep k >= 0), the front reaches the far wall.
void run_dam_break(const DamBreak& d, const std::string& label) {
  Simulation<2, double> sim(d.cfg, d.particles);
  double dt_min = 1, dt_max = 0, vmax = 0;
  while (sim.time() < 1.0) {
    sim.step();
    expect_solver_rules(sim, "step " + std::to_string(sim.steps()));
    dt_min = std::min(dt_min, sim.last_dt());
    dt_max = std::max(dt_max, sim.last_dt());
    const auto& q = sim.particles();
    std::size_t outside = 0, negative = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      vmax = std::max(vmax, norm(q.v[i]));
      if (q.x[i][0] < 0 || q.x[i][0] > DamBreak::L || q.x[i][1] < 0 || q.x[i][1] > DamBreak::Ht) ++outside;
      if (q.p[i] < 0) ++negative;
    }
    ASSERT_EQ(outside, 0u) << "fluid particles outside the tank after step " << sim.steps()
                           << " (t = " << sim.time() << ")";
    ASSERT_EQ(negative, 0u) << "negative pressures after step " << sim.steps();
  }
  // The front has hit the far wall (t > 0.4 s): the test covered the impact, at speeds that made the
  // CFL step shorter than dt_max.
  EXPECT_GT(vmax, 2.0);
  EXPECT_LT(dt_min, 0.005);
  const auto& st = sim.dfsph_stats();
  std::cout << "[dfsph dam break] " << label << " steps " << sim.steps() << " dt " << dt_min << ".." << dt_max
            << " density iterations/step " << double(st.density_iterations) / double(st.steps)
            << " divergence sweeps/step " << double(st.divergence_iterations) / double(st.steps)
            << " max density error " << st.max_density_error << "% max-iteration hits "
            << st.max_iteration_hits << "\n";
}

TEST_P(DfsphWalls, DamBreakLosesNoParticleThroughTheWalls) {
  auto d = dam_break(Method::CellIndex);
  d.cfg.dfsph.wall_pressure = static_cast<DfsphWallPressure>(GetParam());
  run_dam_break(d, "walls " + std::to_string(GetParam()));
}

// The hydrostatic start under DFSPH: rest masses, rho0 over the lattice's kernel sum (no equation of state
// compresses them), so that every lattice site's summation density is rho0. Water 0.8 m deep at 0.02 m in
// a closed 1 m tank, Akinci walls, water's viscosity, CFL steps. Before, the WCSPH start's masses
// (compressed by the default eos, k = 1000 Pa) made such a column explode in its first steps.
TEST(Dfsph, HydrostaticStartKeepsRestMasses) {
  auto scene_json = [](const char* start) {
    auto j = nlohmann::json::parse(R"({"dimension": 2, "precision": "double", "spacing": 0.02,
        "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.001}],
        "solver": {"model": "dfsph", "support": 0.04, "density_kernel": "cubic", "gravity": [0, -9.81]},
        "time": {"stepping": "courant", "dt_max": 0.005, "courant": 0.4},
        "fluids": [{"min": [0, 0], "max": [1, 0.8]}],
        "boundary": {"slip": "no-slip", "model": "akinci",
                     "walls": {"min": [0, 0], "max": [1, 1], "layers": 2, "open_top": false, "weight": "volume"}}})");
    j["initial_pressure"] = start;
    return j;
  };
  std::string src = "column.json";
  const auto hydro = load_scene<2, double>(scene_json("hydrostatic"), src);
  const auto& p = hydro.particles;
  double m_first = -1;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != 0) continue;
    if (m_first < 0) m_first = p.m[i];
    EXPECT_EQ(p.m[i], m_first) << "every fluid particle keeps the rest mass";
  }
  // rho0 over the lattice's kernel sum: rho0 s^2 up to the lattice sum's bias (0.1% here).
  EXPECT_NEAR(m_first, 1000 * 0.02 * 0.02, 0.005 * 1000 * 0.02 * 0.02);
  const auto zero = load_scene<2, double>(scene_json("zero"), src);
  // The first density solve: from the lattice at rho0 it needs fewer sweeps than from "zero"'s masses
  // rho0 s^2, whose lattice density is 0.09% above rho0 (measured 2 sweeps against 63); and nothing flies
  // (compressed masses sent particles out of the tank; measured here: the fastest particle after 41
  // steps 0.61 m/s, 0.64 m/s from zero: the settling of the Akinci walls' bottom row, docs/physics.md
  // "Model 3", not the start).
  auto first_sweeps = [](const Scene<2, double>& sc, double& vmax) {
    Simulation<2, double> sim(sc.solver, sc.particles);
    sim.step();
    const int sweeps = sim.dfsph_stats().last_density_iterations;
    for (int k = 0; k < 40; ++k) sim.step();
    vmax = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      if (sim.particles().kind[i] == 0) vmax = std::max(vmax, norm(sim.particles().v[i]));
    return sweeps;
  };
  double v_hydro = 0, v_zero = 0;
  const int s_hydro = first_sweeps(hydro, v_hydro), s_zero = first_sweeps(zero, v_zero);
  std::cout << "[dfsph start] first density solve: " << s_hydro << " sweeps (hydrostatic), " << s_zero
            << " (zero); fastest particle after 41 steps " << v_hydro << " / " << v_zero << " m/s\n";
  EXPECT_LT(s_hydro, s_zero);
  EXPECT_LT(v_hydro, 1.0);
}

// Same bits: two runs, one and two threads, two neighbour methods and three Verlet skins.
TEST(Dfsph, BitIdenticalAcrossRunsThreadsAndMethods) {
  StepTimings timings;
  auto run = [&timings](Method method, int threads, double skin = -1, bool mirror = false) {
    auto d = dam_break(method);
    if (mirror) d.cfg.dfsph.wall_pressure = DfsphWallPressure::Mirrored;
    if (skin >= 0) d.cfg.verlet_skin = skin;
    ScopedThreads t(threads);
    Simulation<2, double> sim(d.cfg, d.particles);
    sim.run_until(0.3);
    timings = sim.timings();
    return sim.particles();
  };
  const auto a = run(Method::CellIndex, 2);
  // The CFL steps outrun the default skin, so some searches ran at the bare supports (simulation.hpp)
  // and others with the skin; both must give the bits of a search at h every step.
  EXPECT_GT(timings.bare_builds, 0u);
  EXPECT_LT(timings.bare_builds, timings.list_builds);
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 2))) << "two runs";
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 1))) << "one thread";
  EXPECT_TRUE(test::same_state(a, run(Method::KdTree, 2))) << "kd-tree";
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 2, 0.0))) << "no skin";
  EXPECT_TRUE(test::same_state(a, run(Method::CellIndex, 2, 0.6))) << "a wide skin";
  const auto m = run(Method::CellIndex, 2, -1, true);
  EXPECT_FALSE(test::same_state(a, m)) << "mirrored walls changed nothing";
  EXPECT_TRUE(test::same_state(m, run(Method::CellIndex, 1, -1, true))) << "mirrored walls, one thread";
}

// 3D and float: a small column settles with the bound met at every step (and neither stops or yields
// non-finite values).
template <int Dim, class Real>
void settle_small_column() {
  Simulation<Dim, Real> sim(dfsph_water<Dim, Real>(Real(0.05), Real(1), Real(0.01)),
                            test::small_column<Dim, Real>());
  for (int k = 0; k < 40; ++k) {
    sim.step();
    expect_solver_rules(sim, "step " + std::to_string(k + 1));
  }
  EXPECT_LT(test::max_speed(sim.particles()), 0.5) << "a column at rest should stay nearly at rest";
}
TEST(Dfsph, SmallColumn3DDouble) {
  settle_small_column<3, double>();
}
TEST(Dfsph, SmallColumn3DFloat) {
  settle_small_column<3, float>();
}
TEST(Dfsph, SmallColumn2DFloat) {
  settle_small_column<2, float>();
}

// The density pass takes a row's kernel in blocks of 32 pairs on the host, in a loop the compiler vectorizes
// (models/dfsph.hpp). With a support of 3 spacings the rows hold up to 111 pairs, four blocks: every density
// equals the sum of the kernel's own W2 over the particle's neighbours in index order, bit for bit, and a
// double-precision sum within 1e-5.
TEST(Dfsph, DensityPassSumsLongRowsWithTheKernelsBits) {
  using V = Vec<3, float>;
  const float s = 0.05f;
  auto cfg = dfsph_water<3, float>(s, 1.0f, 0.001f);
  cfg.support = 3 * s;
  Particles<3, float> p;
  add_block<3, float>(p, V{}, V{{0.5f, 0.45f, 0.4f}}, s, 0);
  for (std::size_t i = 0; i < p.size(); ++i)  // off the lattice: distances of every size
    for (int a = 0; a < 3; ++a) p.x[i][a] += 0.1f * s * float(std::sin(double(7 * i + 3 * a)));
  Simulation<3, float> sim(cfg, p);
  const std::vector<V> x0(sim.particles().x.begin(), sim.particles().x.end());  // the step's positions
  sim.step();
  const auto& q = sim.particles();
  const float h2 = cfg.support * cfg.support;
  const double sigma = 8 / (3.14159265358979323846 * std::pow(double(cfg.support), 3));  // the 3D cubic's
  std::size_t longest = 0, mismatches = 0;
  double worst = 0;
  with_kernel<3, float>(cfg.density_kernel, cfg.support, [&](const auto w) {
    for (std::size_t i = 0; i < q.size(); ++i) {
      float rho = density_term(w, q.m[i], 0.0f);
      double ref = double(q.m[i]) * double(w.W2(0.0f));
      std::size_t row = 0;
      for (std::size_t j = 0; j < q.size(); ++j) {
        const float r2 = norm2(V(x0[i] - x0[j]));
        if (j == i || r2 > h2) continue;
        ++row;
        rho += q.m[j] * w.W2(r2);
        const double r = std::sqrt(double(r2)), qq = r / double(cfg.support);
        ref +=
            double(q.m[j]) * sigma * (qq <= 0.5 ? 6 * (qq * qq * qq - qq * qq) + 1 : 2 * std::pow(1 - qq, 3));
      }
      longest = std::max(longest, row);
      if (q.rho[i] != rho) ++mismatches;
      worst = std::max(worst, std::abs(double(q.rho[i]) - ref) / ref);
    }
  });
  EXPECT_GT(longest, std::size_t{96}) << "rows should span more than three blocks";
  EXPECT_EQ(mismatches, 0u) << "densities that differ from the scalar sum";
  EXPECT_LT(worst, 1e-5);
}

// The divergence solve's last source pass sums the non-pressure forces in the same walk over the rows
// (DfsphSourceForcesPass): its forces, rate, k and returned error must be those of DfsphNonPressurePass and
// DfsphSourcePass run one after the other, bit for bit, for both density kinds, with wall neighbours (no
// slip, hydrostatic wall pressure, a moving wall's acceleration) and rows of every length. The state is
// made up (random gradients and velocities on a jittered set), so every term carries its own value.
TEST(Dfsph, SourcePassWithTheForcesGivesTheSeparatePassesBits) {
  using V = Vec<3, float>;
  const std::size_t n = 110;
  const float h = 0.3f;
  std::vector<V> x(n), v(n), gsum(n), gwall(n), mv(n), wall_a(n), f_alone(n), f_fused(n);
  std::vector<float> m(n), rho(n), mu(n), rho0(n), vol(n), alpha(n), mk(n), acc(n, 0.0f);
  std::vector<std::uint8_t> kind(n);
  std::uint32_t seed = 12345;
  auto rnd = [&] {  // in [-1, 1)
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 23) - 1.0f;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const float spread = i < 100 ? 0.4f : 2.0f;  // a dense cluster, and a few far out (short rows)
    x[i] = V{{spread * rnd(), spread * rnd(), spread * rnd()}};
    v[i] = V{{rnd(), rnd(), rnd()}};
    kind[i] = i % 4 == 3 ? 1 : 0;  // every fourth a wall particle
    wall_a[i] = kind[i] ? V{{0.5f * rnd(), 0.5f * rnd(), 0.5f * rnd()}} : V{};
    m[i] = 1.0f + 0.2f * rnd();
    rho[i] = 1000.0f + 30.0f * rnd();
    mu[i] = 0.5f + 0.4f * rnd();
    rho0[i] = i % 2 ? 1000.0f : 800.0f;
    vol[i] = m[i] / rho[i];
    alpha[i] = 1e-3f * (1.5f + rnd());
    gsum[i] = V{{rnd(), rnd(), rnd()}};
    gwall[i] = V{{rnd(), rnd(), rnd()}};
    mv[i] = v[i] * m[i];
  }
  std::vector<std::uint64_t> offsets{0};
  std::vector<std::uint32_t> rows, count(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::uint32_t j = 0; j < n; ++j)
      if (j != i && norm2(V(x[i] - x[j])) <= h * h) rows.push_back(j);
    count[i] = static_cast<std::uint32_t>(rows.size() - offsets.back());
    offsets.push_back(rows.size());
  }
  std::vector<V> grads(rows.size());
  for (auto& g : grads) g = V{{rnd(), rnd(), rnd()}};
  const auto [shortest, longest] = std::minmax_element(count.begin(), count.end());
  ASSERT_LT(*shortest, 3u);
  ASSERT_GT(*longest, 20u);

  std::vector<std::uint32_t> fluid;
  for (std::uint32_t i = 0; i < n; ++i)
    if (!kind[i]) fluid.push_back(i);
  const CubicSplineKernel<3, float> w(h);
  for (const bool number : {false, true}) {
    std::vector<float> kappa_alone(n), kappa_fused(n), mk_alone(n), mk_fused(n);
    auto view = [&](std::vector<V>& f, std::vector<float>& kappa, std::vector<float>& mkv) {
      ParticleView<3, float> pv;
      pv.n = n;
      pv.x = x.data();
      pv.v = v.data();
      pv.f = f.data();
      pv.m = m.data();
      pv.rho = rho.data();
      pv.mu = mu.data();
      pv.kind = kind.data();
      pv.rho0 = rho0.data();
      pv.vol = vol.data();
      pv.df_alpha = alpha.data();
      pv.df_kappa = kappa.data();
      pv.df_gsum = gsum.data();
      pv.df_gwall = gwall.data();
      pv.df_mv = mv.data();
      pv.df_mk = mkv.data();
      pv.df_grad = grads.data();
      pv.wall_a = wall_a.data();
      pv.offsets = offsets.data();
      pv.candidates = rows.data();
      pv.within = rows.data();
      pv.within_count = count.data();
      return pv;
    };
    const DfsphSourceRule<float> rule{0.002f, false, false, 0.0f, acc.data(), 5};
    const V gravity{{0.0f, -9.81f, 0.0f}};
    auto forces_of = [&](const ParticleView<3, float>& pv) {
      return DfsphNonPressurePass<3, float, CubicSplineKernel<3, float>>{pv,   w,      gravity, 1e-4f,
                                                                         true, number, true};
    };
    const auto alone = view(f_alone, kappa_alone, mk_alone);
    const auto fused = view(f_fused, kappa_fused, mk_fused);
    run_pass(fluid, forces_of(alone));
    const DfsphSourcePass<3, float, CubicSplineKernel<3, float>> source_alone{alone, w, rule, number};
    const DfsphSourceForcesPass<3, float, CubicSplineKernel<3, float>> both{
        DfsphSourcePass<3, float, CubicSplineKernel<3, float>>{fused, w, rule, number}, forces_of(fused)};
    std::size_t differ = 0, wall_rows = 0;
    for (const std::uint32_t i : fluid) {
      const float e_alone = source_alone(i), e_fused = both(i);
      differ += e_alone != e_fused || kappa_alone[i] != kappa_fused[i] || mk_alone[i] != mk_fused[i];
      for (int a = 0; a < 3; ++a) differ += f_alone[i][a] != f_fused[i][a];
      for (auto* it = alone.row_begin(i); it != alone.row_end(i); ++it) wall_rows += kind[*it];
    }
    EXPECT_EQ(differ, 0u) << (number ? "number" : "mass") << " density";
    EXPECT_GT(wall_rows, 10u);
    // The check sees a change: the forces without the walls' hydrostatic term differ.
    auto plain = forces_of(fused);
    plain.hydrostatic = false;
    run_pass(fluid, plain);
    std::size_t changed = 0;
    for (const std::uint32_t i : fluid) changed += f_alone[i][0] != f_fused[i][0];
    EXPECT_GT(changed, 0u);
  }
}

// The conjugate-gradient density solve (models/dfsph_cg.hpp) on the deep column, where Jacobi is slow (the
// pressure reaches the bottom one row a sweep): at 8 ms steps with hydrostatic walls, started from 0.85 of
// the last step's pressure, it meets the bound in less than half the iterations, stops at max_iterations
// no more often, and gives rho0 g d in the lower half and the bottom row.
TEST(Dfsph, CgDensitySolveTakesTheDeepColumnInFewerIterations) {
  const ColumnRun jacobi = settle_column(column(DfsphWallPressure::Hydrostatic, 0.008), false);
  const ColumnRun cg = settle_column(column(DfsphWallPressure::Hydrostatic, 0.008), false, true, 0.85);
  EXPECT_LT(cg.sweeps, 0.5 * jacobi.sweeps);
  EXPECT_LE(cg.hits, jacobi.hits);
  EXPECT_NEAR(cg.p_mid, 1.0, 0.05);
  EXPECT_NEAR(cg.p_bot, 1.0, 0.05);
  EXPECT_LT(cg.kinetic, cg.kinetic_bound) << "the column should settle";
}

// The CG solve on the 2D dam break: no particle out of the tank through the impact, every solve within its
// rules, no negative pressure (k is clamped at 0: run_dam_break); the same bits for one and two threads, on
// the host-emulated device and through a checkpoint; and not the Jacobi bits.
TEST(Dfsph, CgDensitySolveHoldsTheDamBreakAndItsBits) {
  auto d = dam_break(Method::CellIndex);
  d.cfg.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
  d.cfg.dfsph.warm_start_scale = 0.85;
  run_dam_break(d, "cg");
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
  auto jacobi = d.cfg;
  jacobi.dfsph.density_solver = DfsphDensitySolver::Jacobi;
  Simulation<2, double> j(jacobi, d.particles);
  for (int k = 0; k < 40; ++k) j.step();
  EXPECT_FALSE(test::same_state(a, j.particles())) << "the CG solve gave the Jacobi bits";
}

using test::expect_device_gives_the_cpus_run;

// The device step (the host-emulated device: the CUDA backend's code path over host memory) gives the CPU's
// bits, solver statistics included, and its divergence warm start travels with a checkpoint: a run started
// on the device resumes on the CPU as if uninterrupted.
TEST_P(DfsphWalls, HostDeviceIsBitIdenticalToTheCpuAndResumesAcrossBackends) {
  auto d = dam_break(Method::CellIndex);
  d.cfg.dfsph.wall_pressure = static_cast<DfsphWallPressure>(GetParam());
  expect_device_gives_the_cpus_run(d);
  test::expect_device_run_resumes_on_the_cpu(d);
}

INSTANTIATE_TEST_SUITE_P(Dfsph, DfsphWalls, ::testing::Values(0, 1, 2),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return i.param == 0 ? "Zero" : i.param == 1 ? "Mirrored" : "Hydrostatic";
                         });

// Reordering (neighbors.reorder_every) on the device permutes the divergence warm start with the particles,
// as the CPU does: the same bits, solver state and sweep counts as the CPU's reordering run.
TEST(Dfsph, HostDeviceReorderingGivesTheCpusBits) {
  auto d = dam_break(Method::CellIndex);
  d.cfg.reorder_every = 10;
  EXPECT_EQ(expect_device_gives_the_cpus_run(d), 4u);  // steps 0, 10, 20, 30
}

// 3D float on the device: the same bits as the CPU.
TEST(Dfsph, HostDeviceIsBitIdenticalToTheCpu3DFloat) {
  using V3 = Vec<3, float>;
  const float s = 0.05f;
  auto cfg = dfsph_water<3, float>(s, 1.0f, 0.01f);
  Particles<3, float> p;
  add_block<3, float>(p, V3{}, V3{{0.2f, 0.3f, 0.3f}}, s, 0);
  add_box_walls<3, float>(p, V3{}, V3{{0.4f, 0.3f, 0.4f}}, s, 2, true, 0, 0.0f);
  Simulation<3, float> cpu(cfg, p);
  Simulation<3, float> dev(cfg, p);
  dev.use_backend(Backend::HostDevice);
  for (int k = 0; k < 25; ++k) {
    cpu.step();
    dev.step();
  }
  EXPECT_TRUE(test::same_state(cpu.particles(), dev.particles()));
  EXPECT_EQ(cpu.time(), dev.time());
}

// A solve whose error is not finite stops the run with a diagnosis naming the step, the solve, its sweeps
// and dt; one left above its bound is counted with its step, sweeps, error and bound; one within it is not.
TEST(Dfsph, SolveCheckDiagnosesDivergenceAndCountsMaxIterationHits) {
  DfsphStats st;
  implicit_check_solve(st, DfsphSolveResult{3, 0.0004}, 0.0005, 7, 0.001, "DFSPH constant-density", "sweeps");
  EXPECT_EQ(st.max_iteration_hits, 0u);
  implicit_check_solve(st, DfsphSolveResult{100, 0.002}, 0.0005, 9, 0.001, "DFSPH constant-density",
                       "sweeps");
  EXPECT_EQ(st.max_iteration_hits, 1u);
  EXPECT_EQ(st.last_hit_step, 9u);
  EXPECT_DOUBLE_EQ(st.last_hit_error, 0.2);
  EXPECT_DOUBLE_EQ(st.last_hit_bound, 0.05);
  EXPECT_EQ(st.last_hit_iterations, 100);
  EXPECT_STREQ(st.last_hit_solve, "DFSPH constant-density");
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      implicit_check_solve(st, DfsphSolveResult{4, bad}, 0.001, 12, 0.0025, "IISPH pressure", "iterations");
      ADD_FAILURE() << "no error for " << bad;
    } catch (const SimulationError& e) {
      EXPECT_STREQ(
          e.what(),
          "simulation unstable at step 12: the IISPH pressure solve diverged (average error not finite "
          "after 4 iterations, dt = 0.0025 s)");
    }
  }
  EXPECT_EQ(st.max_iteration_hits, 1u);
}

// A solve that diverges stops the run with a diagnosis naming the step, the solve and the first fluid
// particle the stability check finds bad; the host-emulated device gives the same message.
TEST(Dfsph, DivergedSolveStopsTheRunNamingTheParticle) {
  using V2f = Vec<2, float>;
  const float s = 0.05f;
  auto cfg = dfsph_water<2, float>(s, 1.0f, 0.01f);
  Particles<2, float> p;
  add_block<2, float>(p, V2f{}, V2f{{0.2f, 0.2f}}, s, 0);
  // One particle at 10^19 m/s: the CFL step (2e-21 s) moves it 0.4 d, but its neighbours' k overflow float
  // and the first sweep's kicks leave values that are not finite (measured: 10^18 m/s is caught by the
  // check after the step instead, as an infinite pressure).
  p.v[6] = V2f{{1e19f, 0.0f}};
  add_box_walls<2, float>(p, V2f{}, V2f{{0.4f, 0.4f}}, s, 2, true, 0, 0.0f);
  auto message = [&](bool device) {
    Simulation<2, float> sim(cfg, p);
    if (device) sim.use_backend(Backend::HostDevice);
    try {
      for (int k = 0; k < 5; ++k) sim.step();
    } catch (const SimulationError& e) {
      return std::string(e.what());
    }
    return std::string("stable");
  };
  const std::string cpu = message(false);
  EXPECT_NE(cpu.find("simulation unstable at step "), std::string::npos) << cpu;
  EXPECT_NE(
      cpu.find(
          "the DFSPH divergence-free solve diverged (average error not finite after 1 sweep, dt = 2e-21 s)"),
      std::string::npos)
      << cpu;
  EXPECT_NE(cpu.find("; the first bad particle: particle "), std::string::npos) << cpu;
  EXPECT_EQ(message(true), cpu);
  std::cout << "diagnosis: " << cpu << "\n";
}

// Bad settings name the key and the value.
TEST(Dfsph, BadSettingsAreInputErrors) {
  const auto base = dfsph_water<2, double>(0.02, 1.0, 0.01);
  auto expect_error = [&](auto edit, const std::string& key) { test::expect_edit_invalid(base, edit, key); };
  using C = SolverConfig<2, double>;
  expect_error([](C& c) { c.dfsph.max_density_error = 0; }, "dfsph.max_density_error = 0");
  expect_error([](C& c) { c.dfsph.max_density_error = -1; }, "dfsph.max_density_error = -1");
  expect_error([](C& c) { c.dfsph.max_divergence_error = 0; }, "dfsph.max_divergence_error = 0");
  expect_error([](C& c) { c.dfsph.max_iterations = 0; }, "dfsph.max_iterations = 0");
  expect_error([](C& c) { c.dfsph.min_iterations = -1; }, "dfsph.min_iterations = -1");
  expect_error(
      [](C& c) {
        c.dfsph.min_iterations = 5;
        c.dfsph.max_iterations = 4;
      },
      "dfsph.min_iterations = 5");
  expect_error([](C& c) { c.dfsph.warm_start_scale = 0; }, "dfsph.warm_start_scale = 0");
  expect_error([](C& c) { c.dfsph.warm_start_scale = 1.5; }, "dfsph.warm_start_scale = 1.5");
  // CG needs a symmetric system: one phase's mass density.
  expect_error(
      [](C& c) {
        c.dfsph.density_solver = DfsphDensitySolver::ConjugateGradient;
        c.density = DensityFormulation::Number;
      },
      "dfsph.density_solver = cg");
  expect_error([](C& c) { c.wall_model = WallModel::Adami; }, "boundary.model = adami");
  expect_error([](C& c) { c.wall_model = WallModel::Dynamic; }, "boundary.model = dynamic");
  expect_error([](C& c) { c.phases[0].sigma = 0.07; }, "phases[0].sigma = 0.07");
  // Phases of different rest densities need the number density (accepted: dfsph_phases_test.cpp).
  expect_error(
      [](C& c) {
        c.phases.push_back(c.phases[0]);
        c.phases[1].rest_density = 700;
      },
      "density = mass");
  auto ok = dfsph_water<2, double>(0.02, 1.0, 0.01);
  EXPECT_NO_THROW(ok.validate());
}

// The scene keys: /solver/dfsph, read only for the DFSPH model, unknown keys and bad values named.
std::string scene_error(const std::string& model, const std::string& dfsph) {
  const std::string text = R"({"name": "t", "dimension": 2, "spacing": 0.05,
      "solver": {"model": ")" +
                           model + R"(", "density_kernel": "cubic", "dfsph": )" + dfsph + R"(},
      "fluids": [{"min": [0, 0], "max": [0.2, 0.2]}],
      "boundary": {"model": "akinci", "walls": {"min": [0, 0], "max": [0.4, 0.4], "layers": 2}}})";
  try {
    const auto sc = load_scene<2, double>(nlohmann::json::parse(text), "scene.json");
    EXPECT_EQ(sc.solver.model, Model::Dfsph);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Dfsph, SceneKeys) {
  EXPECT_EQ(scene_error("dfsph", R"({"max_density_error": 0.1, "max_divergence_error": 0.2,
                                     "min_iterations": 3, "max_iterations": 50, "warm_start": false,
                                     "wall_pressure": "hydrostatic"})"),
            "");
  EXPECT_EQ(scene_error("dfsph", R"({"density_solver": "cg", "warm_start_scale": 0.85})"), "");
  const std::pair<std::string, std::string> bad[] = {
      {R"({"max_density_error": 0})", "/solver/dfsph/max_density_error"},
      {R"({"max_divergence_error": -0.1})", "/solver/dfsph/max_divergence_error"},
      {R"({"max_iterations": 0})", "/solver/dfsph/max_iterations"},
      {R"({"min_iterations": 9, "max_iterations": 4})", "/solver/dfsph/min_iterations"},
      {R"({"max_iterations": 4.5})", "/solver/dfsph/max_iterations"},
      {R"({"warmstart": true})", "/solver/dfsph/warmstart"},
      {R"({"wall_pressure": "extrapolated"})", "/solver/dfsph/wall_pressure"},
      {R"({"density_solver": "gmres"})", "/solver/dfsph/density_solver"},
      {R"({"warm_start_scale": 2})", "/solver/dfsph/warm_start_scale"},
      {R"({"warm_start_scale": 0})", "/solver/dfsph/warm_start_scale"}};
  for (const auto& [value, key] : bad) {
    const std::string msg = scene_error("dfsph", value);
    EXPECT_NE(msg.find(key), std::string::npos) << value << " -> " << msg;
    EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  }
  const std::string msg = scene_error("wcsph", "{}");
  EXPECT_NE(msg.find("/solver/dfsph"), std::string::npos) << msg;
}

// The built-in WCSPH scene dam-break-3d switched with `--set /solver/model=dfsph`: one message names each
// setting DFSPH refuses (Adami walls, the artificial viscosity) and the exact --set edits that fit; with
// them the scene loads (a DFSPH scene with Akinci walls), as does the built-in dam-break-3d-dfsph.
TEST(Dfsph, WcsphSceneSwitchedNamesTheSetEditsItNeeds) {
  auto load = [](const std::string& name, const std::vector<std::string>& edits) -> std::string {
    std::string src;
    auto j = read_scene_json(name, src);
    apply_scene_edits(j, edits, src);
    try {
      const auto sc = load_scene<3, float>(j, src);
      EXPECT_EQ(sc.solver.model, Model::Dfsph);
      EXPECT_EQ(sc.solver.wall_model, WallModel::Akinci);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string msg = load("dam-break-3d", {"/solver/model=dfsph"});
  EXPECT_NE(msg.find("/boundary/model is \"adami\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("/solver/artificial_viscosity/alpha is 0.01"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Add: --set /boundary/model=akinci --set /solver/artificial_viscosity/alpha=0"),
            std::string::npos)
      << msg;
  EXPECT_EQ(load("dam-break-3d",
                 {"/solver/model=dfsph", "/boundary/model=akinci", "/solver/artificial_viscosity/alpha=0"}),
            "");
  // The continuity density is named too (dam-break-3d sums its density).
  const std::string cont =
      load("dam-break-3d", {"/solver/model=dfsph", "/boundary/model=akinci",
                            "/solver/artificial_viscosity/alpha=0", "/solver/density=continuity"});
  EXPECT_NE(cont.find("Add: --set /solver/density=mass"), std::string::npos) << cont;
  // The built-in 3D DFSPH scene at about 10^5 fluid particles.
  std::string src;
  const auto j = read_scene_json("dam-break-3d-dfsph", src);
  const auto sc = load_scene<3, float>(j, src);
  EXPECT_EQ(sc.solver.model, Model::Dfsph);
  EXPECT_EQ(sc.solver.wall_model, WallModel::Akinci);
  std::size_t fluid = 0;
  for (const auto k : sc.particles.kind) fluid += k == 0;
  EXPECT_EQ(fluid, 46u * 46u * 46u);  // SPlisHSPlasH's DamBreakModel at its ~10^5 resolution
}

}  // namespace
}  // namespace cellsph
