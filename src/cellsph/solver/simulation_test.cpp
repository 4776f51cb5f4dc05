// Solver tests against independent references: conservation laws, hydrostatics (rho g H), bit-for-bit
// determinism and checkpoint/resume. Small particle counts with the all-pairs reference search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/solver/boundaries.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

using V2 = Vec<2, double>;

// A free blob of fluid (no walls, no gravity) with jittered positions and random velocities.
Particles<2, double> blob(int nx, double s, std::uint32_t seed, int phases = 1) {
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{nx * s, nx * s}}, s, 0);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.x[i] += V2{{u(gen), u(gen)}} * (0.1 * s);
    p.v[i] = V2{{u(gen), u(gen)}} * 0.5;
    if (phases > 1 && p.x[i][0] > nx * s / 2) p.phase[i] = 1;
  }
  return p;
}

SolverConfig<2, double> base_config(Model model) {
  SolverConfig<2, double> c;
  c.model = model;
  c.search.method = Method::AllPairs;
  c.support = 0.05;
  c.gravity = V2{};
  c.phases[0].rest_density = 1000;
  c.phases[0].mass = 1000 * 0.02 * 0.02;
  c.phases[0].viscosity = 1;
  c.eos.kind = EosKind::Tait;
  c.eos.stiffness = 2000;
  c.time.dt = 2e-4;
  if (model == Model::Wcsph) {
    c.density_kernel = KernelKind::CubicSpline;
    c.pressure_kernel = KernelKind::CubicSpline;
    c.eos.kind = EosKind::Ratio;
    c.eos.stiffness = 2e4;
  }
  return c;
}

using test::wcsph_water;

using test::same_state;
using test::ViscousBox;
using test::weakly_viscous_box;

class BothModels : public ::testing::TestWithParam<Model> {};

TEST_P(BothModels, MassConservedExactly) {
  ScopedThreads one(1);  // small runs; thread independence is tested separately
  auto cfg = base_config(GetParam());
  Simulation<2, double> sim(cfg, blob(8, 0.02, 1));
  const double m0 = sim.total_mass();
  const auto masses = sim.particles().m;
  for (int s = 0; s < 30; ++s) sim.step();
  EXPECT_EQ(sim.total_mass(), m0);
  EXPECT_EQ(sim.particles().m, masses);
  EXPECT_EQ(sim.particles().size(), 64u);
}

TEST_P(BothModels, LinearMomentumConservedToRoundOff) {
  ScopedThreads one(1);  // small runs; thread independence is tested separately
  // Pairwise antisymmetric forces (eq. 8a-b averaged; the write-up's symmetric pressure and Monaghan
  // viscosity) leave sum m v unchanged up to the rounding of the per-particle sums.
  auto cfg = base_config(GetParam());
  cfg.phases.push_back(cfg.phases[0]);
  cfg.phases[1].viscosity = 3;
  cfg.phases[1].mass *= 1.5;  // a second phase with other mass and viscosity
  Simulation<2, double> sim(cfg, blob(9, 0.02, 7, 2));
  const V2 p0 = sim.momentum();
  double scale = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    scale += sim.particles().m[i] * norm(sim.particles().v[i]);
  double max_f = 0;
  for (int s = 0; s < 60; ++s) {
    sim.step();
    for (const auto& f : sim.particles().f) max_f = std::max(max_f, norm(f));
  }
  const V2 p1 = sim.momentum();
  // Forces must not be trivially zero for this to mean anything.
  EXPECT_GT(max_f * sim.last_dt() * 60, 1e-3 * scale);
  EXPECT_LT(norm(p1 - p0), 1e-12 * scale)
      << "p0 = " << p0[0] << "," << p0[1] << " p1 = " << p1[0] << "," << p1[1];
}

TEST_P(BothModels, BitIdenticalAcrossRunsAndThreadCounts) {
  auto cfg = base_config(GetParam());
  cfg.phases[0].sigma = 0.5;  // exercise the colour field too
  cfg.box.enabled = true;
  cfg.box.lo = V2{{-0.05, -0.05}};
  cfg.box.hi = V2{{0.25, 0.25}};
  cfg.gravity = SolverConfig<2, double>::gravity_default();
  auto run = [&](int threads) {
    ScopedThreads t(threads);
    Simulation<2, double> sim(cfg, blob(8, 0.02, 3));
    for (int s = 0; s < 20; ++s) sim.step();
    return sim.particles();
  };
  const auto a = run(1), b = run(1), c = run(2);
  EXPECT_TRUE(same_state(a, b));
  EXPECT_TRUE(same_state(a, c));
}

TEST_P(BothModels, CheckpointResumeIsBitIdentical) {
  ScopedThreads one(1);  // small runs; thread independence is tested separately
  auto cfg = base_config(GetParam());
  cfg.time.mode = TimeStepping::Courant;
  cfg.time.dt_max = 1e-3;
  cfg.gravity = SolverConfig<2, double>::gravity_default();
  cfg.planes.push_back({V2{{0, 1}}, -0.02});
  Simulation<2, double> full(cfg, blob(8, 0.02, 5));
  for (int s = 0; s < 25; ++s) full.step();
  const auto saved = full.particles();
  const auto state = full.integrator_state();
  for (int s = 0; s < 25; ++s) full.step();

  Simulation<2, double> resumed(cfg, blob(8, 0.02, 5));
  resumed.restore(saved, state, "test");
  EXPECT_EQ(resumed.steps(), 25u);
  for (int s = 0; s < 25; ++s) resumed.step();
  EXPECT_TRUE(same_state(full.particles(), resumed.particles()));
  EXPECT_EQ(full.time(), resumed.time());
  EXPECT_EQ(full.steps(), resumed.steps());
}

INSTANTIATE_TEST_SUITE_P(Solver, BothModels, ::testing::Values(Model::PaperMultiphase, Model::Wcsph),
                         [](const ::testing::TestParamInfo<Model>& pi) {
                           return std::string(model_name(pi.param));
                         });

// The file format's own checks (magic, version, dimension, precision, fields, checksum) are tested in
// io/checkpoint_test.cpp and io/simulation_checkpoint_test.cpp; these are the solver's.
TEST(Checkpoint, RestoreRejectsParticlesThatDoNotFitAndKeepsItsState) {
  auto cfg = base_config(Model::Wcsph);
  Simulation<2, double> a(cfg, blob(4, 0.02, 1));
  Simulation<2, double> b(cfg, blob(5, 0.02, 1));
  b.step();
  const auto before = b.particles();
  auto expect_input_error = [&](const Particles<2, double>& p, const std::string& what) {
    try {
      b.restore(p, a.integrator_state(), "file.ckpt");
      ADD_FAILURE() << "no InputError for " << what;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("file.ckpt"), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  expect_input_error(a.particles(), "holds 16 particles, the scene has 25");
  auto bad = b.particles();
  bad.phase[3] = 7;
  expect_input_error(bad, "particle 3 has phase 7");
  bad = b.particles();
  bad.kind[4] = 9;
  expect_input_error(bad, "particle 4 has phase 0 / kind 9");
  EXPECT_TRUE(same_state(before, b.particles()));
  EXPECT_EQ(b.steps(), 1u);
}

TEST(Solver, LeapfrogHalfStepInitialisation) {
  // A single particle under gravity: with v(t0 - dt/2) initialised, leap-frog is exact for constant
  // acceleration: x(t) = x0 + v0 t + g t^2 / 2 at every step.
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.gravity = V2{{0, -9.81}};
  cfg.time.dt = 0.01;
  Particles<2, double> p;
  add_particle<2, double>(p, V2{{0, 0}}, 0, ParticleKind::Fluid, 0, V2{{1, 2}});
  Simulation<2, double> sim(cfg, p);
  for (int s = 0; s < 50; ++s) sim.step();
  const double t = sim.time();
  EXPECT_NEAR(sim.particles().x[0][0], 1 * t, 1e-12);
  EXPECT_NEAR(sim.particles().x[0][1], 2 * t - 9.81 * t * t / 2, 1e-12);
}

TEST(Solver, UnstableRunStopsWithDiagnosis) {
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.time.dt = 0.5;  // far beyond eq. 12
  cfg.eos.stiffness = 1e7;
  cfg.domain_set = true;
  cfg.domain_lo = V2{{-1, -1}};
  cfg.domain_hi = V2{{1, 1}};
  Simulation<2, double> sim(cfg, blob(6, 0.02, 2));
  try {
    for (int s = 0; s < 20; ++s) sim.step();
    FAIL() << "no SimulationError";
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step "), std::string::npos) << msg;
    EXPECT_NE(msg.find("particle "), std::string::npos) << msg;
  }
}

// A continuity density driven through zero stops the run naming the particle and the density (it once
// went on, and the particle left through a wall a few steps later: SPHERIC Test 2 with Fourtakas).
TEST(Solver, NonPositiveDensityStopsTheRun) {
  auto cfg = base_config(Model::Wcsph);
  cfg.density_evolution = DensityEvolution::Continuity;
  cfg.phases[0].viscosity = 0;
  cfg.time.dt = 1e-3;
  Particles<2, double> p;
  // Two particles 0.02 m apart flying apart at 100 m/s: d rho / dt = m v_ij . grad W ~ -4e6 kg/m^3/s.
  add_particle<2, double>(p, V2{{0, 0}}, 0, ParticleKind::Fluid, 0, V2{{-100, 0}});
  add_particle<2, double>(p, V2{{0.02, 0}}, 0, ParticleKind::Fluid, 0, V2{{100, 0}});
  for (auto& r : p.rho) r = 1000;
  Simulation<2, double> sim(cfg, p);
  try {
    sim.step();
    FAIL() << "no SimulationError; density " << sim.particles().rho[0];
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step 1 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("particle 0 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("is not positive"), std::string::npos) << msg;
  }
}

// A speed whose square overflows (finite, but the Courant step from it is 0) stops the run instead of
// stepping by 0 for ever.
TEST(Solver, SpeedWhoseSquareOverflowsStopsTheRun) {
  auto cfg = base_config(Model::Wcsph);
  cfg.time.mode = TimeStepping::Courant;
  Particles<2, double> p;
  add_particle<2, double>(p, V2{{0, 0}}, 0, ParticleKind::Fluid, 0, V2{{1e160, 0}});
  Simulation<2, double> sim(cfg, p);
  try {
    for (int s = 0; s < 3; ++s) sim.step();
    FAIL() << "no SimulationError; t = " << sim.time();
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step 1 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("particle 0 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("its square overflows (the Courant step would be 0)"), std::string::npos) << msg;
  }
}

TEST(Solver, RejectsBadInput) {
  auto cfg = base_config(Model::Wcsph);
  cfg.support = -1;
  auto make = [&] { Simulation<2, double> sim(cfg, blob(3, 0.02, 1)); };
  EXPECT_THROW(make(), InputError);
  cfg = base_config(Model::Wcsph);
  auto p = blob(3, 0.02, 1);
  p.phase[4] = 7;
  try {
    Simulation<2, double> sim(cfg, p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particle 4 has phase 7"), std::string::npos) << e.what();
  }
}

TEST(Walls, PlaneCollisionProjectsReflectsAndRubs) {
  V2 x{{0.3, -0.01}}, v{{2, -1}};
  plane_collision<2, double>(x, v, V2{{0, 1}}, 0.0, 0.5, 0.25);
  EXPECT_DOUBLE_EQ(x[1], 0.0);       // projected onto the wall
  EXPECT_DOUBLE_EQ(v[1], 0.5);       // -e vn
  EXPECT_DOUBLE_EQ(v[0], 2 * 0.75);  // wet friction
  V2 y{{0.3, 0.2}}, w{{2, -1}};
  plane_collision<2, double>(y, w, V2{{0, 1}}, 0.0, 0.5, 0.25);
  EXPECT_EQ(w, (V2{{2, -1}}));  // no contact, no change
}

TEST(Walls, BoxClampsAndDamps) {
  V2 x{{1.2, -1.3}}, v{{3, -4}};
  box_collision<2, double>(x, v, V2{{-1, -1}}, V2{{1, 1}}, 0.01, -0.5);
  EXPECT_DOUBLE_EQ(x[0], 0.99);
  EXPECT_DOUBLE_EQ(x[1], -0.99);
  EXPECT_DOUBLE_EQ(v[0], -1.5);
  EXPECT_DOUBLE_EQ(v[1], 2.0);
}

// Hydrostatic tank (2D, WCSPH, boundary particles): after settling, the mean density is within 1% of rest
// density and the pressure of the bottom row within 5% of rho0 g (H - y). Both are averaged over the
// steps of the window [0.5 s, 1 s]: the weakly compressible column keeps ringing acoustically (period
// 4H/c = 0.05 s) at an amplitude of a few percent, and the mean over many periods is the state it rings
// about.
class WallModels : public ::testing::TestWithParam<WallModel> {};

TEST_P(WallModels, HydrostaticTankSettlesToRhoGH) {
  const double s = 0.02, W = 0.2, H = 0.3, rho0 = 1000, g = 9.81;
  // c: Mach 0.1 for the fastest free-fall speed
  SolverConfig<2, double> cfg = wcsph_water(s, 10 * std::sqrt(2 * g * H));
  cfg.wall_model = GetParam();
  cfg.search.method = Method::AllPairs;
  cfg.phases[0].viscosity = 20;
  cfg.domain_set = true;
  cfg.domain_lo = V2{{-0.1, -0.1}};
  cfg.domain_hi = V2{{W + 0.1, 2 * H}};
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{W, H}}, s, 0);
  // Walls on the fluid's lattice, as thick as the support, weighted like fluid.
  add_box_walls<2, double>(p, V2{{0, 0}}, V2{{W, H + 2 * s}}, s, 2, true, 0, rho0 * s * s);
  ScopedThreads one(1);  // ~400 particles: thread start-up would dominate
  Simulation<2, double> sim(cfg, p);
  sim.run_until(0.5);

  double rho_mean = 0, p_bottom = 0, ref_bottom = 0;
  int samples = 0;
  while (sim.time() < 1.0) {
    sim.step();
    const auto& q = sim.particles();
    double rho_sum = 0, pb = 0, rb = 0;
    int nf = 0, nb = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != 0) continue;
      rho_sum += q.rho[i];
      ++nf;
      if (q.x[i][1] < s) {
        pb += q.p[i];
        rb += rho0 * g * (H - q.x[i][1]);
        ++nb;
      }
    }
    ASSERT_GT(nb, 0);
    rho_mean += rho_sum / nf;
    p_bottom += pb / nb;
    ref_bottom += rb / nb;
    ++samples;
  }
  rho_mean /= samples;
  p_bottom /= samples;
  ref_bottom /= samples;
  EXPECT_NEAR(rho_mean, rho0, 0.01 * rho0);
  EXPECT_NEAR(p_bottom, ref_bottom, 0.05 * ref_bottom);
  EXPECT_LT(sim.kinetic_energy(), 1e-3 * sim.total_mass() * g * H) << "not settled";
  std::cout << "[hydrostatic] walls " << wall_model_name(GetParam()) << " steps " << sim.steps()
            << " mean rho " << rho_mean << " bottom p " << p_bottom << " ref " << ref_bottom << " KE "
            << sim.kinetic_energy() << "\n";
}

// Issue 3's open problem: weakly viscous water (mu = 0.5 Pa s, no artificial viscosity) in a closed box of
// two layers of wall particles (0.5 m square, closed, filled to 0.4 m), the two-phase scene's coarse
// resolution (h = 0.05 m, 2 spacings) with one phase, WCSPH with the hydrostatic tank's clamped ratio EOS (c
// = 10 sqrt(2 g H)). With Akinci walls it blows up within 0.6-1.8 s (docs/physics.md, "Scene stability"); the
// same water between the paper's planes settles. Here: 10^4 steps (Courant, 4.8 s): no blow-up
// (SimulationError), every particle inside the box, and the energy (kinetic + gravitational + the EOS's
// internal energy) never above its value after the first step by more than half of m g H. Measured: Akinci
// walls leave the domain at step 2267 (t = 1.09 s; step 2835 with the former Monaghan-form viscous operator).
// Adami walls held with the Monaghan form (excess 0.23 m g H at 10^4 steps, still sloshing), but with
// Morris's laminar operator (issue 14), which damps the compressive part of the flow less, they blow up too:
// step 6366 (t = 3.05 s, energy 392 J -> 3957 J). So with Adami or Akinci walls the blow-up is asserted as
// the open problem; the built-in WCSPH scenes add an artificial viscosity (alpha 0.01), which this box lacks.
// The paper model (eq. 8a/8b, same box and EOS) blows up with either wall model: Akinci walls at t = 1.15 s,
// Adami walls at step 7671 (t = 3.67 s, a particle through the floor); asserted as the open problem it is.
// The cause (docs/physics.md, "Scene stability", by energy bookkeeping): the wall's own pressure term,
// -m_i m_w p_w / rho_w^2 grad W (Adami) or the mirrored p_b / rho_i^2 (Akinci), is not the gradient of an
// energy, since p_w is not a function of the wall's own kernel-sampled density; it does net positive work
// (Adami, WCSPH: +1221 J over the 10^4 steps against -1070 J of viscosity). Not the time step: halving it
// keeps the gain. Dynamic walls (p_w = EOS of the wall's summation density) make every force conservative:
// there the energy, the walls' internal energy included, never rises by more than 2% of m g H and the
// water comes to rest (kinetic energy below 10^-3 m g H), both models; measured E0 - 1.4 J and 0.011 J
// (WCSPH), excess 0.005 m g H and 0.008 J (paper).
TEST_P(WallModels, WeaklyViscousBoxHoldsTenThousandSteps) {
  for (Model model : {Model::Wcsph, Model::PaperMultiphase}) {
    const double s = ViscousBox::s, L = ViscousBox::L, H = ViscousBox::H, rho0 = ViscousBox::rho0,
                 g = ViscousBox::g;
    ViscousBox box = weakly_viscous_box(model, GetParam(), 0.5);
    const SolverConfig<2, double>& cfg = box.cfg;
    const std::size_t fluid = box.fluid_count;
    ScopedThreads one(1);
    Simulation<2, double> sim(cfg, std::move(box.particles));
    // Internal energy of the ratio EOS per unit mass: int_rho0^rho p / r^2 dr = k (ln(rho/rho0) + rho0/rho -
    // 1) / rho0, for rho > rho0 (clamped: 0 below).
    // Dynamic walls store internal energy too (their density is a summation like the fluid's): counted.
    const double k = cfg.eos.stiffness;
    const bool dynamic = GetParam() == WallModel::Dynamic;
    auto energy = [&] {
      const auto& q = sim.particles();
      double e = 0;
      for (std::size_t i = 0; i < q.size(); ++i) {
        if (i < fluid) e += q.m[i] * (norm2(q.v[i]) / 2 + g * q.x[i][1]);
        if ((i < fluid || dynamic) && q.rho[i] > rho0)
          e += q.m[i] * k * (std::log(q.rho[i] / rho0) + rho0 / q.rho[i] - 1) / rho0;
      }
      return e;
    };
    const double mass = sim.total_mass(), tol = 0.5 * mass * g * H;
    sim.step();
    const double e0 = energy();
    double e_max = e0;
    bool blew_up = false;
    try {
      for (int n = 1; n < 10000; ++n) {
        sim.step();
        if (n % 50 == 0) e_max = std::max(e_max, energy());
      }
    } catch (const SimulationError& e) {
      blew_up = true;
      std::cout << "[weak viscosity] " << model_name(model) << ", walls " << wall_model_name(GetParam())
                << ": " << e.what() << "\n";
    }
    e_max = std::max(e_max, energy());
    double outside = 0;
    for (std::size_t i = 0; i < fluid; ++i)
      for (int a = 0; a < 2; ++a)
        outside = std::max({outside, -sim.particles().x[i][a], sim.particles().x[i][a] - L});
    std::cout << "[weak viscosity] " << model_name(model) << ", walls " << wall_model_name(GetParam())
              << " steps " << sim.steps() << " t " << sim.time() << " E0 " << e0 << " max excess "
              << (e_max - e0) / (mass * g * H) << " m g H, E_end " << energy() << " KE "
              << sim.kinetic_energy() << " outside " << outside << "\n";
    if (dynamic) {
      // Walls that do no net work: the energy only falls and the water comes to rest, both models.
      EXPECT_FALSE(blew_up) << model_name(model);
      EXPECT_EQ(sim.steps(), 10000u);
      EXPECT_LE(e_max - e0, 0.02 * mass * g * H) << model_name(model);
      EXPECT_LT(sim.kinetic_energy(), 1e-3 * mass * g * H) << model_name(model) << " not at rest";
      EXPECT_LE(outside, s / 2);
      continue;
    }
    // The open problem, where it remains (Akinci and Adami walls, both models): fails if it goes away, so
    // that the docs get updated.
    EXPECT_TRUE(blew_up || e_max - e0 > tol) << model_name(model) << ", walls " << wall_model_name(GetParam())
                                             << " no longer blow up: update docs/physics.md";
  }
}

// Adami (and dynamic) walls gather their fluid neighbours from the fluid rows (atomics, then each list
// sorted): the results must still be bit-identical for 1 and 2 threads and for every neighbour method.
TEST(Walls, AdamiBitIdenticalAcrossThreadsAndMethods) {
  for (WallModel walls : {WallModel::Adami, WallModel::Dynamic}) {
    const double s = 0.05, rho0 = 1000;
    SolverConfig<2, double> cfg = wcsph_water(s, 20);
    cfg.wall_model = walls;
    cfg.no_slip = true;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{0.4, 0.6}}, s, 0);
    add_box_walls<2, double>(p, V2{{0, 0}}, V2{{1.0, 1.0}}, s, 2, true, 0, rho0 * s * s);
    std::vector<Particles<2, double>> out;
    for (auto [threads, method] : {std::pair{1, Method::CellIndex}, std::pair{2, Method::CellIndex},
                                   std::pair{2, Method::AllPairs}, std::pair{2, Method::KdTree}}) {
      ScopedThreads t(threads);
      SolverConfig<2, double> c = cfg;
      c.search.method = method;
      Simulation<2, double> sim(c, p);
      for (int n = 0; n < 300; ++n) sim.step();
      out.push_back(sim.particles());
    }
    for (std::size_t k = 1; k < out.size(); ++k)
      EXPECT_TRUE(same_state(out[0], out[k])) << wall_model_name(walls) << " run " << k;
    // The wall state is computed (a bottom wall particle under the column carries pressure).
    double pmax = 0;
    for (std::size_t i = 0; i < out[0].size(); ++i)
      if (out[0].kind[i] == 1) pmax = std::max(pmax, out[0].p[i]);
    EXPECT_GT(pmax, 0.5 * rho0 * 9.81 * 0.6) << wall_model_name(walls);
  }
}

// Adami wall states are recomputed every step from the fluid, so a resumed run (both models) matches an
// uninterrupted one bit for bit.
TEST(Walls, AdamiCheckpointResumeIsBitIdentical) {
  for (auto [model, walls] :
       {std::pair{Model::Wcsph, WallModel::Adami}, std::pair{Model::PaperMultiphase, WallModel::Adami},
        std::pair{Model::Wcsph, WallModel::Dynamic}}) {
    const double s = 0.05, rho0 = 1000;
    SolverConfig<2, double> cfg = wcsph_water(s, 20);
    cfg.model = model;
    cfg.wall_model = walls;
    cfg.no_slip = true;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{0.4, 0.6}}, s, 0);
    add_box_walls<2, double>(p, V2{{0, 0}}, V2{{1.0, 1.0}}, s, 2, true, 0, rho0 * s * s);
    ScopedThreads one(1);
    Simulation<2, double> full(cfg, p);
    for (int n = 0; n < 100; ++n) full.step();
    const auto saved = full.particles();
    const auto state = full.integrator_state();
    for (int n = 0; n < 100; ++n) full.step();
    Simulation<2, double> resumed(cfg, p);
    resumed.restore(saved, state, "test");
    for (int n = 0; n < 100; ++n) resumed.step();
    EXPECT_TRUE(same_state(full.particles(), resumed.particles()))
        << model_name(model) << ", walls " << wall_model_name(walls);
    EXPECT_EQ(full.time(), resumed.time());
  }
}

TEST(Walls, AdamiNeedsGlobalSteps) {
  for (WallModel walls : {WallModel::Adami, WallModel::Dynamic}) {
    SolverConfig<2, double> cfg = base_config(Model::PaperMultiphase);
    cfg.wall_model = walls;
    cfg.time.mode = TimeStepping::PerParticle;
    EXPECT_THROW(cfg.validate(), InputError) << wall_model_name(walls);
  }
}

INSTANTIATE_TEST_SUITE_P(Walls, WallModels,
                         ::testing::Values(WallModel::Akinci, WallModel::Adami, WallModel::Dynamic),
                         [](const auto& p) { return std::string(wall_model_name(p.param)); });

// No-slip walls against Stokes' first problem: fluid moving at u0 over a wall at rest (the same as a
// plate started impulsively under fluid at rest) has, far from the ends, the velocity profile
// u(y, t) = u0 erf(y / (2 sqrt(nu t))), y measured from the wall surface (half a spacing below the
// first fluid layer). Free-slip walls leave the layer moving at u0. Both models; no gravity.
// Measured worst |u - u_ref| / u0 over the layer (y < 2 sqrt(nu t)), WCSPH / paper model: 0.113 / 0.082
// at this spacing (h = 2 spacings), 0.096 / 0.059 at half of it: the simulated layer is thinner (a little
// slip at the wall: boundary particles at rest, not mirrored velocities) and converges slowly. Free slip:
// 0.001. Hence 0.15 u0 with no slip (no friction at all would be 0.94 u0 off at the wall) and 0.01 u0
// without. Adami walls (boundary.model adami: the wall takes minus the kernel average of its fluid
// neighbours' velocities, a mirror of the flow) must do at least as well as Akinci's at rest; measured
// 0.083 (WCSPH) / 0.040 (paper) against 0.113 / 0.082.
TEST(Walls, NoSlipMatchesStokesFirstProblem) {
  const double s = 0.02, rho0 = 1000, mu = 10, nu = mu / rho0, u0 = 0.05, t_end = 1.0;
  for (Model model : {Model::Wcsph, Model::PaperMultiphase}) {
    double worst_akinci = 0;
    for (WallModel walls : {WallModel::Akinci, WallModel::Adami}) {
      for (bool no_slip : {true, false}) {
        // Free slip with Adami walls (measured 0.0011 / 0.0008 u0, WCSPH / paper) is left
        // out of CI (the runs dominate this test, under the sanitizers too).
        if (!no_slip && walls == WallModel::Adami) continue;
        SolverConfig<2, double> cfg = wcsph_water(s, 1.0);  // c = 1 m/s = 20 u0
        cfg.model = model;
        cfg.wall_model = walls;
        cfg.gravity = V2{};
        cfg.phases[0].viscosity = mu;
        cfg.no_slip = no_slip;
        Particles<2, double> p;
        // The block stops short of the end walls: it moves only u0 t = 5 cm, so it never meets them (a
        // wall would stop the fluid behind a compression wave travelling at c).
        add_block<2, double>(p, V2{{0.3, 0}}, V2{{2.1, 0.6}}, s, 0);
        const std::size_t fluid = p.size();
        p.v.assign(fluid, V2{{u0, 0}});
        add_box_walls<2, double>(p, V2{{0, 0}}, V2{{2.4, 1.0}}, s, 2, true, 0, rho0 * s * s);
        p.v.resize(p.size(), V2{});
        Simulation<2, double> sim(cfg, std::move(p));
        sim.run_until(t_end);

        // Mean x velocity per lattice row in the middle third (away from the end walls).
        const double t = sim.time(), delta = 2 * std::sqrt(nu * t);
        std::vector<double> sum(30, 0.0), count(30, 0.0);
        for (std::size_t i = 0; i < fluid; ++i) {
          const auto& x = sim.particles().x[i];
          if (x[0] < 0.9 || x[0] > 1.5) continue;
          const auto row = static_cast<std::size_t>(std::floor(x[1] / s));
          if (row < sum.size()) {
            sum[row] += sim.particles().v[i][0];
            count[row] += 1;
          }
        }
        double worst = 0;
        for (std::size_t row = 0; row < 10; ++row) {  // y up to 0.2 m = 2 delta: the boundary layer
          ASSERT_GT(count[row], 0);
          const double y = (static_cast<double>(row) + 0.5) * s;
          const double u = sum[row] / count[row];
          const double ref = no_slip ? u0 * std::erf(y / delta) : u0;
          worst = std::max(worst, std::abs(u - ref) / u0);
          EXPECT_NEAR(u, ref, (no_slip ? 0.15 : 0.01) * u0)
              << (no_slip ? "no-slip" : "free-slip") << " y = " << y << " model " << static_cast<int>(model)
              << " walls " << wall_model_name(walls);
        }
        std::cout << "[stokes] model " << static_cast<int>(model) << " walls " << wall_model_name(walls)
                  << (no_slip ? " no-slip" : " free-slip")
                  << ": worst |u - u_ref| / u0 over the boundary layer " << worst << "\n";
        if (no_slip && walls == WallModel::Akinci) worst_akinci = worst;
        if (no_slip && walls == WallModel::Adami) {
          EXPECT_LE(worst, worst_akinci) << "model " << static_cast<int>(model);
        }
      }
    }
  }
}

// Verlet lists are a speed-up only: every pair is re-tested at h, so any skin (0: a search every step)
// gives the same bits, while the number of searches drops with the skin.
TEST(VerletLists, SkinChangesSearchCountNotResults) {
  std::vector<std::vector<V2>> runs;
  std::vector<std::uint64_t> builds;
  for (double skin : {0.0, 0.15, 0.5}) {
    const double s = 0.1, rho0 = 1000;
    SolverConfig<2, double> cfg = wcsph_water(s, 10 * std::sqrt(2 * 9.81 * 2));
    cfg.verlet_skin = skin;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{1, 2}}, s, 0);
    add_box_walls<2, double>(p, V2{{0, 0}}, V2{{4, 3}}, s, 2, true, 0, rho0 * s * s);
    Simulation<2, double> sim(cfg, std::move(p));
    for (int k = 0; k < 300; ++k) sim.step();
    runs.push_back(sim.particles().x);
    builds.push_back(sim.timings().list_builds);
  }
  EXPECT_EQ(runs[0], runs[1]);
  EXPECT_EQ(runs[0], runs[2]);
  // With reordering on too: the reorders follow the step count, not the list rebuilds.
  std::vector<std::vector<V2>> reordered;
  for (double skin : {0.0, 0.15, 0.5}) {
    const double s = 0.1, rho0 = 1000;
    SolverConfig<2, double> cfg = wcsph_water(s, 10 * std::sqrt(2 * 9.81 * 2));
    cfg.verlet_skin = skin;
    cfg.reorder_every = 25;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{1, 2}}, s, 0);
    add_box_walls<2, double>(p, V2{{0, 0}}, V2{{4, 3}}, s, 2, true, 0, rho0 * s * s);
    Simulation<2, double> sim(cfg, std::move(p));
    for (int k = 0; k < 300; ++k) sim.step();
    EXPECT_EQ(sim.timings().reorders, 12u);
    reordered.push_back(sim.particles().x);
  }
  EXPECT_EQ(reordered[0], reordered[1]);
  EXPECT_EQ(reordered[0], reordered[2]);
  EXPECT_NE(reordered[0], runs[0]);  // another order (and other last bits)
  EXPECT_EQ(builds[0], 300u);
  EXPECT_LT(builds[1], builds[0]);
  EXPECT_LT(builds[2], builds[1]);
}

// The same conservation law in 3D and in single precision (a smoke test of the other instantiations).
TEST(Solver3D, MomentumConservedBothModels) {
  for (Model model : {Model::PaperMultiphase, Model::Wcsph}) {
    SolverConfig<3, float> cfg;
    cfg.model = model;
    cfg.search.method = Method::AllPairs;
    cfg.support = 0.05f;
    cfg.gravity = Vec<3, float>{};
    cfg.phases[0].mass = 1000 * 0.02f * 0.02f * 0.02f;
    cfg.phases[0].viscosity = 1;
    cfg.eos.stiffness = 2000;
    cfg.time.dt = 2e-4f;
    Particles<3, float> p;
    add_block<3, float>(p, Vec<3, float>{}, Vec<3, float>{{0.1f, 0.1f, 0.1f}}, 0.02f, 0);
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> u(-1, 1);
    for (auto& v : p.v) v = Vec<3, float>{{u(gen), u(gen), u(gen)}};
    ScopedThreads one(1);
    Simulation<3, float> sim(cfg, p);
    const auto p0 = sim.momentum();
    for (int k = 0; k < 20; ++k) sim.step();
    EXPECT_LT(norm(sim.momentum() - p0), 1e-5f * sim.total_mass()) << model_name(model);
    EXPECT_GT(sim.particles().rho[0], 0.0f);
  }
}

// Per-particle power-of-two steps: one particle falling under gravity speeds up, so eq. 12 refines its
// level several times. With the Exact step-change correction its position stays on the parabola to
// round-off; eq. 13 as printed drifts off it (the difference is reported, not hidden).
double falling_particle_error(StepChangeCorrection corr, int* levels_seen) {
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.gravity = V2{{0, -9.81}};
  cfg.eos.stiffness = 1e-3;  // sound speed ~0: eq. 12's velocity term decides the level
  cfg.time.mode = TimeStepping::PerParticle;
  cfg.time.dt_max = 0.01;
  cfg.time.max_level = 10;
  cfg.time.force = 100;  // keep the force limit out of the way
  cfg.time.correction = corr;
  Particles<2, double> p;
  add_particle<2, double>(p, V2{{0, 0}}, 0, ParticleKind::Fluid, 0, V2{{1, 2}});
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, p);
  double worst = 0;
  int lo = 99, hi = -1;
  while (sim.time() < 1.0) {
    sim.step();
    const double t = static_cast<double>(sim.particles().tick[0]) * 0.01 / 1024;
    const auto& x = sim.particles().x[0];
    worst = std::max({worst, std::abs(x[0] - t), std::abs(x[1] - (2 * t - 9.81 * t * t / 2))});
    lo = std::min(lo, sim.particles().level[0]);
    hi = std::max(hi, sim.particles().level[0]);
  }
  *levels_seen = hi - lo + 1;
  return worst;
}

TEST(PerParticleSteps, StepChangesKeepConstantAccelerationExact) {
  int levels = 0;
  const double exact = falling_particle_error(StepChangeCorrection::Exact, &levels);
  EXPECT_GE(levels, 3) << "the test must change level";
  EXPECT_LT(exact, 1e-10);
  const double printed = falling_particle_error(StepChangeCorrection::Printed, &levels);
  std::cout << "[per-particle] max position error: exact correction " << exact << " m, eq. 13 as printed "
            << printed << " m\n";
  EXPECT_GT(printed, 1e-6);
}

TEST(PerParticleSteps, CheckpointResumeIsBitIdentical) {
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.gravity = SolverConfig<2, double>::gravity_default();
  cfg.time.mode = TimeStepping::PerParticle;
  cfg.time.dt_max = 2e-3;
  cfg.time.max_level = 8;
  ScopedThreads one(1);
  Simulation<2, double> full(cfg, blob(8, 0.02, 9));
  for (int s = 0; s < 30; ++s) full.step();
  const auto saved = full.particles();
  const auto state = full.integrator_state();
  for (int s = 0; s < 30; ++s) full.step();
  Simulation<2, double> resumed(cfg, blob(8, 0.02, 9));
  resumed.restore(saved, state, "test");
  for (int s = 0; s < 30; ++s) resumed.step();
  EXPECT_TRUE(same_state(full.particles(), resumed.particles()));
  EXPECT_EQ(full.time(), resumed.time());
}

// Per-particle steps evaluate densities (and CSF normals) only where the due particles' forces read them.
// That must be a pure optimisation: the reference is the same scene with every density and normal
// computed in every sub-step (set_full_passes, the computation before the work sets), run in the same
// process. A two-phase column collapsing in a tank of boundary particles with a plane floor, interface
// tension of both kinds, a low sound speed so that eq. 12's velocity and force terms spread the particles
// over several levels.
struct PerParticleRun {
  Particles<2, double> p;
  StepTimings t;
  double time = 0;
  std::vector<std::uint8_t> last_due;  // 1 for the particles advanced by the last sub-step
  int levels = 0;                      // distinct levels seen
};

PerParticleRun per_particle_column(TensionModel tension, bool full, int threads) {
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.gravity = SolverConfig<2, double>::gravity_default();
  cfg.phases.push_back(cfg.phases[0]);
  cfg.phases[1].rest_density = 1500;
  cfg.phases[1].mass = 1500 * 0.02 * 0.02;
  cfg.phases[1].color = 2;
  cfg.phases[0].sigma = cfg.phases[1].sigma = 0.5;
  cfg.tension = tension;
  cfg.eos.kind = EosKind::Tait;
  cfg.eos.stiffness = 300;                                   // c = 1.4 m/s: alpha h / c = 10 ms
  cfg.phases[0].viscosity = cfg.phases[1].viscosity = 0.02;  // viscous limit 16 ms
  cfg.time.mode = TimeStepping::PerParticle;
  cfg.time.dt_max = 16e-3;
  cfg.time.max_level = 6;
  cfg.search.method = Method::CellIndex;
  cfg.planes.push_back({V2{{0, 1}}, 0.0});
  Particles<2, double> p;
  const double s = 0.02;
  add_block<2, double>(p, V2{{0, 0}}, V2{{0.16, 0.3}}, s, 0);
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-2, 2);  // alpha h / |v| from 5 ms up: several levels
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.x[i][1] > 0.2) p.phase[i] = 1;
    p.v[i] = V2{{u(gen), u(gen)}};
  }
  add_box_walls<2, double>(p, V2{{0, 0}}, V2{{0.5, 0.4}}, s, 2, true, 0, 1000 * s * s);
  ScopedThreads use(threads);
  Simulation<2, double> sim(cfg, p);
  sim.set_full_passes(full);
  PerParticleRun r;
  std::vector<int> seen(cfg.time.max_level + 1, 0);
  for (int k = 0; k < 150; ++k) {
    const auto ticks = sim.particles().tick;
    sim.step();
    r.last_due.assign(ticks.size(), 0);
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      r.last_due[i] = ticks[i] != sim.particles().tick[i];
      if (sim.particles().kind[i] == 0) seen[static_cast<std::size_t>(sim.particles().level[i])] = 1;
    }
  }
  r.p = sim.particles();
  r.t = sim.timings();
  r.time = sim.time();
  for (int v : seen) r.levels += v;
  return r;
}

TEST(PerParticleSteps, WorkSetsAreBitIdenticalToFullPasses) {
  for (auto tension : {TensionModel::Paper, TensionModel::Csf, TensionModel::Akinci}) {
    SCOPED_TRACE(std::string(tension_model_name(tension)));
    const auto full = per_particle_column(tension, true, 1);
    const auto sets = per_particle_column(tension, false, 1);
    EXPECT_GE(sets.levels, 2) << "the particles must spread over levels for the sets to be partial";
    EXPECT_EQ(full.time, sets.time);
    // Integrated state: every particle, bit for bit.
    auto same = [](const auto& a, const auto& b) {
      return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
    };
    EXPECT_TRUE(same(full.p.x, sets.p.x));
    EXPECT_TRUE(same(full.p.v, sets.p.v));
    EXPECT_TRUE(same(full.p.f, sets.p.f));
    EXPECT_TRUE(same(full.p.level, sets.p.level));
    EXPECT_TRUE(same(full.p.tick, sets.p.tick));
    // Densities of the particles the last sub-step advanced (computed by both); the others keep, with the
    // work sets, the density of their last evaluation.
    std::size_t compared = 0;
    for (std::size_t i = 0; i < full.p.size(); ++i) {
      if (!sets.last_due[i]) continue;
      ++compared;
      EXPECT_EQ(std::memcmp(&full.p.rho[i], &sets.p.rho[i], sizeof(double)), 0) << "particle " << i;
      EXPECT_EQ(std::memcmp(&full.p.p[i], &sets.p.p[i], sizeof(double)), 0) << "particle " << i;
    }
    EXPECT_GT(compared, 0u);
    // Same forces evaluated, fewer densities (and normals).
    EXPECT_EQ(full.t.force_evals, sets.t.force_evals);
    EXPECT_LT(sets.t.density_evals, full.t.density_evals);
    EXPECT_LT(sets.t.force_evals, full.t.density_evals)
        << "some sub-steps must advance only part of the fluid";
    if (tension != TensionModel::Paper) {
      EXPECT_LT(sets.t.normal_evals, full.t.normal_evals);
    }
    std::cout << "[per-particle] " << tension_model_name(tension) << ": " << full.t.force_evals
              << " force evaluations; densities " << sets.t.density_evals << " (sets) vs "
              << full.t.density_evals << " (full), normals " << sets.t.normal_evals << " vs "
              << full.t.normal_evals << ", " << sets.levels << " levels\n";
    // Thread count: the marks are set concurrently, the results must not depend on it.
    const auto two = per_particle_column(tension, false, 2);
    EXPECT_TRUE(same_state(sets.p, two.p));
    EXPECT_EQ(sets.t.density_evals, two.t.density_evals);
  }
}

TEST(PerParticleSteps, RejectedForWcsph) {
  auto cfg = base_config(Model::Wcsph);
  cfg.time.mode = TimeStepping::PerParticle;
  auto make = [&] { Simulation<2, double> sim(cfg, blob(3, 0.02, 1)); };
  EXPECT_THROW(make(), InputError);
}

// Two fluids of rest density 1000 and 2000 on one lattice (masses rho0 s^2), at rest. Eq. 7 sums masses,
// so next to the interface the light fluid is given up to half the heavy one's density and vice versa; the
// number density of Solenthaler & Pajarola (2008) gives each particle its own rest density. Reference:
// the rest densities themselves (an unstrained lattice), measured on particles at least h from the edge
// of the block.
double worst_density_error(DensityFormulation d) {
  const double s = 0.02;
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.density = d;
  cfg.density_kernel = KernelKind::CubicSpline;
  cfg.support = 2 * s;
  cfg.phases.push_back(cfg.phases[0]);
  cfg.phases[1].rest_density = 2000;
  cfg.phases[1].mass = 2000 * s * s;
  cfg.phases[0].mass = 1000 * s * s;
  cfg.time.dt = 1e-6;
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{0.4, 0.4}}, s, 0);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.x[i][1] > 0.2) p.phase[i] = 1;
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, p);
  sim.step();
  const auto& q = sim.particles();
  double worst = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const auto& x = q.x[i];
    if (x[0] < 2 * s || x[0] > 0.4 - 2 * s || x[1] < 2 * s || x[1] > 0.4 - 2 * s) continue;
    const double rho0 = cfg.phases[static_cast<std::size_t>(q.phase[i])].rest_density;
    worst = std::max(worst, std::abs(q.rho[i] - rho0) / rho0);
  }
  return worst;
}

TEST(TwoPhase, NumberDensityKeepsTheDensityJumpSharp) {
  const double mass = worst_density_error(DensityFormulation::Mass);
  const double number = worst_density_error(DensityFormulation::Number);
  std::cout << "[two-phase] worst density error at the interface: eq. 7 " << 100 * mass
            << "%, number density " << 100 * number << "%\n";
  EXPECT_GT(mass, 0.1);
  EXPECT_LT(number, 0.01);
}

// One phase at rest in a tank of boundary particles: the number density m_i sum_j W_ij V_j / V_i must equal
// eq. 7's sum_j m_j W_ij, wall particles included (same mass, same rest density: the two formulations are the
// same sum). Reference: eq. 7 evaluated by the same solver with density "mass". The wall term once counted
// a wall particle by its volume V_b instead of V_b / V_i, so fluid next to a wall had ~half its density and
// the two-phase tank blew up in a few steps.
TEST(TwoPhase, NumberDensityEqualsMassDensityForOnePhaseWithWalls) {
  const double s = 0.02;
  std::vector<double> rho[2];
  for (int k = 0; k < 2; ++k) {
    auto cfg = base_config(Model::PaperMultiphase);
    cfg.density = k == 0 ? DensityFormulation::Mass : DensityFormulation::Number;
    cfg.density_kernel = KernelKind::CubicSpline;
    cfg.support = 2 * s;
    cfg.phases[0].mass = 1000 * s * s;
    cfg.time.dt = 1e-6;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{0.2, 0.2}}, s, 0);
    add_box_walls<2, double>(p, V2{{0, 0}}, V2{{0.2, 0.3}}, s, 2, true, 0, 1000 * s * s);
    ScopedThreads one(1);
    Simulation<2, double> sim(cfg, p);
    sim.step();
    const auto& q = sim.particles();
    for (std::size_t i = 0; i < q.size(); ++i)
      if (q.kind[i] == 0) rho[k].push_back(q.rho[i]);
  }
  ASSERT_EQ(rho[0].size(), rho[1].size());
  for (std::size_t i = 0; i < rho[0].size(); ++i) ASSERT_NEAR(rho[1][i], rho[0][i], 1e-9 * rho[0][i]) << i;
}

// The paper's walls in a run: a blob dropped into a box of four planes (inelastic collision, wet friction,
// projection) never ends a step outside, and its energy falls (collisions and friction only remove it).
TEST(Walls, PaperPlanesHoldAFallingBlob) {
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.gravity = SolverConfig<2, double>::gravity_default();
  cfg.planes = {{V2{{0, 1}}, -0.3}, {V2{{1, 0}}, -0.05}, {V2{{-1, 0}}, -0.25}};
  cfg.domain_set = true;
  cfg.domain_lo = V2{{-0.05, -0.3}};
  cfg.domain_hi = V2{{0.25, 0.3}};
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, blob(8, 0.02, 4));
  auto energy = [&] {
    double e = sim.kinetic_energy();
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      e += sim.particles().m[i] * 9.81 * (sim.particles().x[i][1] + 0.3);
    return e;
  };
  const double e0 = energy();
  for (int s = 0; s < 2500; ++s) {
    sim.step();
    for (const auto& x : sim.particles().x) {
      ASSERT_GE(x[1], -0.3) << "step " << s;
      ASSERT_GE(x[0], -0.05);
      ASSERT_LE(x[0], 0.25);
    }
  }
  EXPECT_LT(energy(), e0);
  EXPECT_GT(sim.time(), 0.49);  // it really fell onto the floor (free fall from y = 0 takes 0.25 s)
}

// Single and double precision follow the same trajectory closely over a short run.
TEST(Solver, FloatTracksDouble) {
  auto cd = base_config(Model::Wcsph);
  SolverConfig<2, float> cf;
  cf.model = Model::Wcsph;
  cf.search.method = Method::AllPairs;
  cf.support = 0.05f;
  cf.gravity = Vec<2, float>{};
  cf.phases[0].mass = static_cast<float>(cd.phases[0].mass);
  cf.phases[0].viscosity = 1;
  cf.density_kernel = cd.density_kernel;
  cf.pressure_kernel = cd.pressure_kernel;
  cf.eos.kind = cd.eos.kind;
  cf.eos.stiffness = static_cast<float>(cd.eos.stiffness);
  cf.time.dt = static_cast<float>(cd.time.dt);
  const auto pd = blob(6, 0.02, 8);
  Particles<2, float> pf;
  for (std::size_t i = 0; i < pd.size(); ++i)
    add_particle<2, float>(pf,
                           Vec<2, float>{{static_cast<float>(pd.x[i][0]), static_cast<float>(pd.x[i][1])}}, 0,
                           ParticleKind::Fluid, 0,
                           Vec<2, float>{{static_cast<float>(pd.v[i][0]), static_cast<float>(pd.v[i][1])}});
  ScopedThreads one(1);
  Simulation<2, double> sd(cd, pd);
  Simulation<2, float> sf(cf, pf);
  for (int s = 0; s < 50; ++s) {
    sd.step();
    sf.step();
  }
  double worst = 0;
  for (std::size_t i = 0; i < pd.size(); ++i)
    for (int a = 0; a < 2; ++a)
      worst = std::max(worst, std::abs(static_cast<double>(sf.particles().x[i][a]) - sd.particles().x[i][a]));
  EXPECT_LT(worst, 1e-5);  // metres, after particles moved ~5 mm
}

// Interface tension on a disc of fluid 1 (colour 1) in fluid 0 (colour 0), both at rest on a lattice with
// no pressure: integrating a continuum surface force sigma kappa n delta over the upper half of a circle
// of radius R gives sigma (1/R) (2R) = 2 sigma, pointing down (in 2D, independent of R). Sum of the
// particle forces over y > centre, against that reference. Eq. 9 as printed is reported, not asserted:
// its lap C carries the normal derivative of |grad C|, which does not integrate to the curvature term
// (measured about twice the reference).
double half_disc_tension(TensionModel model) {
  const double s = 0.01, L = 0.3, R = 0.08, sigma = 1;
  auto cfg = base_config(Model::PaperMultiphase);
  cfg.support = 3 * s;
  cfg.density_kernel = KernelKind::CubicSpline;
  cfg.pressure_kernel = KernelKind::CubicSpline;
  cfg.eos.kind = EosKind::Ratio;
  cfg.eos.stiffness = 1e-9;  // no pressure: the force is the tension alone
  cfg.phases[0].mass = 1000 * s * s;
  cfg.phases[0].viscosity = 0;
  cfg.phases[0].color = 0;
  cfg.phases[0].sigma = sigma;
  cfg.phases.push_back(cfg.phases[0]);
  cfg.phases[1].color = 1;
  cfg.tension = model;
  cfg.tension_threshold = 0;
  cfg.time.dt = 1e-9;
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{L, L}}, s, 0);
  const V2 c{{L / 2, L / 2}};
  for (std::size_t i = 0; i < p.size(); ++i)
    if (norm(p.x[i] - c) < R) p.phase[i] = 1;
  ScopedThreads one(1);
  Simulation<2, double> sim(cfg, p);
  sim.step();
  V2 f{};
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    if (sim.particles().x[i][1] > c[1]) f += sim.particles().f[i];
  // Symmetric about the vertical axis (eq. 9 normalises the noise of grad C deep inside a phase, so only
  // the CSF force, exactly zero there, is symmetric to round-off).
  if (model == TensionModel::Csf) {
    EXPECT_NEAR(f[0], 0, 1e-9);
  }
  return f[1];
}

// A free drop (the droplet scene: a 0.2 m square, no gravity, no walls) under Akinci 2013 tension: its
// pair forces are exact opposites, so momentum stays at round-off while the square rounds into a disc
// (outline in 8 sectors within 7% of R = sqrt(area / pi); the corners start at 1.24 R). Eq. 9 on the same
// drop is printed for comparison: its forces do not sum to zero and the drop drifts.
TEST(InterfaceTension, AkinciFreeDropConservesMomentumAndRounds) {
  const double s = 0.01, R = std::sqrt(0.2 * 0.2 / std::numbers::pi);
  for (TensionModel tension : {TensionModel::Akinci, TensionModel::Paper}) {
    SolverConfig<2, double> cfg;
    cfg.model = Model::PaperMultiphase;
    cfg.search.method = Method::CellIndex;
    cfg.density_kernel = KernelKind::CubicSpline;
    cfg.pressure_kernel = KernelKind::CubicSpline;
    cfg.support = 2 * s;
    cfg.gravity = V2{};
    cfg.phases[0].rest_density = 1000;
    cfg.phases[0].mass = 1000 * s * s;
    cfg.phases[0].viscosity = 0.5;
    cfg.phases[0].sigma = tension == TensionModel::Akinci ? 0.1 : 1.0;  // the droplet scene's, then eq. 9's
    cfg.tension = tension;
    cfg.eos.kind = EosKind::Ratio;
    cfg.eos.stiffness = 1e4;
    cfg.time.mode = TimeStepping::Courant;
    cfg.time.dt_max = 1e-3;
    Particles<2, double> p;
    add_block<2, double>(p, V2{{-0.1, -0.1}}, V2{{0.1, 0.1}}, s, 0);
    Simulation<2, double> sim(cfg, std::move(p));
    sim.run_until(2.0);
    const auto& q = sim.particles();
    V2 c{}, mom{};
    double mass = 0, abs_mom = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      c += q.x[i] * q.m[i];
      mass += q.m[i];
      mom += q.v[i] * q.m[i];
      abs_mom += q.m[i] * norm(q.v[i]);
    }
    c = c / mass;
    std::vector<double> outline(8, 0.0);
    for (std::size_t i = 0; i < q.size(); ++i) {
      const V2 d = q.x[i] - c;
      const auto sector = static_cast<std::size_t>(std::floor((std::atan2(d[1], d[0]) + std::numbers::pi) /
                                                              (2 * std::numbers::pi) * 8)) %
                          8;
      outline[sector] = std::max(outline[sector], norm(d) + s / 2);
    }
    const auto [lo, hi] = std::minmax_element(outline.begin(), outline.end());
    std::cout << "[free drop] " << (tension == TensionModel::Akinci ? "akinci" : "eq. 9")
              << ": |momentum| / sum m|v| = " << norm(mom) / abs_mom << ", centre drift " << norm(c)
              << " m, outline " << *lo / R << " .. " << *hi / R << " R\n";
    if (tension != TensionModel::Akinci) continue;
    EXPECT_LT(norm(mom), 1e-10 * abs_mom);
    EXPECT_LT(norm(c), 1e-10);
    EXPECT_GT(*lo, 0.93 * R);
    EXPECT_LT(*hi, 1.07 * R);
  }
}

TEST(InterfaceTension, HalfDiscForceMatchesTwoSigma) {
  const double csf = half_disc_tension(TensionModel::Csf);
  const double paper = half_disc_tension(TensionModel::Paper);
  std::cout << "[tension] half-disc force (reference -2 N/m): CSF " << csf << ", eq. 9 " << paper << "\n";
  // within 2.5%: measured -2.0035 (h = 3 spacings, R = 8 spacings); -1.89 before CSF's curvature was
  // normalised by the kernel sum of the neighbours that have a normal
  EXPECT_NEAR(csf, -2.0, 0.05);
}

}  // namespace
}  // namespace cellsph
