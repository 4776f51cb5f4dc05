// A Simulation written to a checkpoint file and read back into a fresh Simulation of the same config
// continues bit for bit (the `--resume` path of `cellsph run`), and files that do not fit are refused with
// an InputError naming the file.
#include "cellsph/io/simulation_checkpoint.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <type_traits>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/checkpoint.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

// A block of fluid in a box with gravity, velocities jittered so that every step changes every field.
template <int Dim, class Real>
Particles<Dim, Real> block(int nx) {
  using V = Vec<Dim, Real>;
  Particles<Dim, Real> p;
  V lo{}, hi{};
  for (int a = 0; a < Dim; ++a) hi[a] = Real(0.02) * Real(nx);
  add_block<Dim, Real>(p, lo, hi, Real(0.02), 0);
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (auto& v : p.v)
    for (int a = 0; a < Dim; ++a) v[a] = Real(u(gen));
  return p;
}

template <int Dim, class Real>
SolverConfig<Dim, Real> config(Model model) {
  SolverConfig<Dim, Real> c;
  c.model = model;
  c.search.method = Method::CellIndex;
  c.support = Real(0.05);
  c.phases[0].rest_density = 1000;
  c.phases[0].mass = Real(1000 * std::pow(0.02, Dim));
  c.phases[0].viscosity = Real(0.5);
  c.eos.stiffness = 2000;
  c.time.mode = TimeStepping::Courant;
  c.time.dt_max = Real(1e-3);
  for (int a = 0; a < Dim; ++a) {
    Vec<Dim, Real> n{};
    n[a] = 1;
    c.planes.push_back({n, Real(-0.01)});
  }
  return c;
}

template <int Dim, class Real>
bool same_fields(const Particles<Dim, Real>& a, const Particles<Dim, Real>& b) {
  bool same = a.size() == b.size();
  a.for_each_field([&](std::string_view name, const auto& fa) {
    b.for_each_field([&](std::string_view nb, const auto& fb) {
      if constexpr (std::is_same_v<decltype(fa), decltype(fb)>)
        if (name == nb)
          same = same && fa.size() == fb.size() &&
                 std::memcmp(fa.data(), fb.data(), fa.size() * sizeof(fa[0])) == 0;
    });
  });
  return same;
}

template <int Dim, class Real>
void resume_is_bit_identical(Model model, bool continuity = false) {
  ScopedThreads one(1);
  test::TempDir dir("sim_ckpt");
  auto cfg = config<Dim, Real>(model);
  if (continuity) {
    // The density is then state, integrated step by step: the checkpoint must carry it.
    cfg.density_evolution = DensityEvolution::Continuity;
    cfg.density_diffusion.kind = DensityDiffusion::Fourtakas;
    cfg.artificial_viscosity.alpha = Real(0.05);
  }
  Simulation<Dim, Real> full(cfg, block<Dim, Real>(5));
  for (int s = 0; s < 20; ++s) full.step();
  const std::string extra("caller\0bytes", 12);  // any bytes, a NUL included
  write_simulation_checkpoint(full, extra, dir / "c.ckpt");
  const auto header = read_checkpoint_header(dir / "c.ckpt");
  EXPECT_EQ(header.dim, Dim);
  EXPECT_EQ(header.real_size, int(sizeof(Real)));
  EXPECT_EQ(header.step, 20u);
  EXPECT_EQ(header.time, double(full.time()));
  for (int s = 0; s < 20; ++s) full.step();

  // The caller's bytes alone, without a Simulation to restore into (the Python module's resume).
  EXPECT_EQ(read_simulation_checkpoint_extra(dir / "c.ckpt"), extra);
  Simulation<Dim, Real> resumed(cfg, block<Dim, Real>(5));
  EXPECT_EQ(read_simulation_checkpoint(dir / "c.ckpt", resumed), extra);
  EXPECT_EQ(resumed.steps(), 20u);
  for (int s = 0; s < 20; ++s) resumed.step();
  EXPECT_TRUE(same_fields(full.particles(), resumed.particles()));
  EXPECT_EQ(full.time(), resumed.time());
  EXPECT_EQ(full.last_dt(), resumed.last_dt());
  EXPECT_EQ(full.steps(), resumed.steps());
}

// The paper model's leap-frog keeps v(t - dt/2) and the last dt: both must survive the file.
TEST(SimulationCheckpoint, ResumeIsBitIdenticalPaper2DDouble) {
  resume_is_bit_identical<2, double>(Model::PaperMultiphase);
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalPaper3DFloat) {
  resume_is_bit_identical<3, float>(Model::PaperMultiphase);
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalWcsph2DFloat) {
  resume_is_bit_identical<2, float>(Model::Wcsph);
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalWcsphContinuityFourtakas2DDouble) {
  resume_is_bit_identical<2, double>(Model::Wcsph, true);
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalWcsphContinuityFourtakas3DFloat) {
  resume_is_bit_identical<3, float>(Model::Wcsph, true);
}

// The implicit models' resume cases: a block of water (spacing 0.02 m, 8 x 8 in 2D, 4^3 in 3D) with
// jittered velocities in a closed box of Akinci walls twice its height, water's viscosity, reordered every
// 5 steps.
template <int Dim, class Real>
SolverConfig<Dim, Real> implicit_box_config(Model model) {
  SolverConfig<Dim, Real> cfg = test::dfsph_water<Dim, Real>(Real(0.02), Real(0.001), Real(2e-3));
  cfg.model = model;
  cfg.reorder_every = 5;
  return cfg;
}
template <int Dim, class Real>
Particles<Dim, Real> implicit_box() {
  using V = Vec<Dim, Real>;
  const Real s = Real(0.02);
  const int nx = Dim == 2 ? 8 : 4;
  V lo{}, hi{}, box{};
  for (int a = 0; a < Dim; ++a) {
    hi[a] = s * Real(nx);
    box[a] = a == Dim - 1 ? 2 * hi[a] : hi[a];
  }
  Particles<Dim, Real> p;
  add_block<Dim, Real>(p, lo, hi, s, 0);
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (auto& v : p.v)
    for (int a = 0; a < Dim; ++a) v[a] = Real(u(gen));
  add_box_walls<Dim, Real>(p, lo, box, s, 2, false, 0, Real(1000 * std::pow(double(s), Dim)));
  return p;
}

// DFSPH: the box above. The divergence solve's warm start (the solver state dfsph_kappa_v) is not a particle
// field: the checkpoint must carry it. The test shows it does matter: a resume that drops it (restore without
// the solver state, as the format-1 checkpoints did) differs from the uninterrupted run.
template <int Dim, class Real>
void dfsph_resume_is_bit_identical() {
  ScopedThreads one(1);
  test::TempDir dir("sim_ckpt_dfsph");
  const auto cfg = implicit_box_config<Dim, Real>(Model::Dfsph);
  const auto make = [] { return implicit_box<Dim, Real>(); };
  Simulation<Dim, Real> full(cfg, make());
  for (int k = 0; k < 12; ++k) full.step();
  write_simulation_checkpoint(full, "", dir / "c.ckpt");
  const auto at_checkpoint = full.particles();
  const auto state_at_checkpoint = full.solver_state();
  const auto integrator_at_checkpoint = full.integrator_state();
  int nonzero = 0;
  for (const Real k : state_at_checkpoint.dfsph_kappa_v) nonzero += k != 0;
  EXPECT_GT(nonzero, 0) << "the divergence solve left no warm start: the test would prove nothing";
  for (int k = 0; k < 12; ++k) full.step();

  Simulation<Dim, Real> resumed(cfg, make());
  read_simulation_checkpoint(dir / "c.ckpt", resumed);
  EXPECT_TRUE(same_fields(at_checkpoint, resumed.particles()));
  EXPECT_EQ(resumed.solver_state().dfsph_kappa_v, state_at_checkpoint.dfsph_kappa_v);
  for (int k = 0; k < 12; ++k) resumed.step();
  EXPECT_TRUE(same_fields(full.particles(), resumed.particles()));
  EXPECT_EQ(full.solver_state().dfsph_kappa_v, resumed.solver_state().dfsph_kappa_v);
  EXPECT_EQ(full.time(), resumed.time());
  EXPECT_EQ(full.steps(), resumed.steps());

  Simulation<Dim, Real> cold(cfg, make());
  cold.restore(at_checkpoint, integrator_at_checkpoint, "test");  // without the solver state: 0
  for (int k = 0; k < 12; ++k) cold.step();
  EXPECT_FALSE(same_fields(full.particles(), cold.particles())) << "the warm start made no difference";
}

TEST(SimulationCheckpoint, ResumeIsBitIdenticalDfsph2DDouble) {
  dfsph_resume_is_bit_identical<2, double>();
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalDfsph3DFloat) {
  dfsph_resume_is_bit_identical<3, float>();
}

// IISPH: the same box; its warm start is the pressure field, which the checkpoint carries with the
// particles. 12 steps, checkpoint, 12 more against the uninterrupted run.
template <int Dim, class Real>
void iisph_resume_is_bit_identical() {
  ScopedThreads one(1);
  test::TempDir dir("sim_ckpt_iisph");
  const auto cfg = implicit_box_config<Dim, Real>(Model::Iisph);
  const auto make = [] { return implicit_box<Dim, Real>(); };
  Simulation<Dim, Real> full(cfg, make());
  for (int k = 0; k < 12; ++k) full.step();
  write_simulation_checkpoint(full, "", dir / "c.ckpt");
  for (int k = 0; k < 12; ++k) full.step();
  Simulation<Dim, Real> resumed(cfg, make());
  read_simulation_checkpoint(dir / "c.ckpt", resumed);
  for (int k = 0; k < 12; ++k) resumed.step();
  EXPECT_TRUE(same_fields(full.particles(), resumed.particles()));
  EXPECT_EQ(full.time(), resumed.time());
  EXPECT_EQ(full.dfsph_stats().last_density_iterations, resumed.dfsph_stats().last_density_iterations);
}

TEST(SimulationCheckpoint, ResumeIsBitIdenticalIisph2DDouble) {
  iisph_resume_is_bit_identical<2, double>();
}
TEST(SimulationCheckpoint, ResumeIsBitIdenticalIisph3DFloat) {
  iisph_resume_is_bit_identical<3, float>();
}

std::string load_error(const std::filesystem::path& path, Simulation<2, double>& sim) {
  try {
    read_simulation_checkpoint(path, sim);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SimulationCheckpoint, MismatchesAreInputErrorsNamingTheFile) {
  test::TempDir dir("sim_ckpt_err");
  const auto cfg = config<2, double>(Model::Wcsph);
  Simulation<2, double> a(cfg, block<2, double>(4)), b(cfg, block<2, double>(5));
  a.step();
  write_simulation_checkpoint(a, "", dir / "a.ckpt");
  b.step();
  const auto before = b.particles();
  const auto file = (dir / "a.ckpt").string();

  auto m = load_error(dir / "a.ckpt", b);
  EXPECT_NE(m.find("checkpoint '" + file + "': holds 16 particles, the scene has 25"), std::string::npos)
      << m;
  EXPECT_TRUE(same_fields(before, b.particles())) << "untouched on error";
  EXPECT_EQ(b.steps(), 1u);

  // A 3D or single-precision file, and one of the bare format without the integrator state.
  Simulation<3, double> three(config<3, double>(Model::Wcsph), block<3, double>(2));
  write_simulation_checkpoint(three, "", dir / "3d.ckpt");
  m = load_error(dir / "3d.ckpt", b);
  EXPECT_NE(m.find((dir / "3d.ckpt").string()), std::string::npos) << m;
  EXPECT_NE(m.find("3D run, cannot continue a 2D run"), std::string::npos) << m;
  Simulation<2, float> single(config<2, float>(Model::Wcsph), block<2, float>(5));
  write_simulation_checkpoint(single, "", dir / "f.ckpt");
  m = load_error(dir / "f.ckpt", b);
  EXPECT_NE(m.find("precision mismatch: file holds float"), std::string::npos) << m;
  write_checkpoint(b.particles(), {0.5, 3, ""}, dir / "bare.ckpt");
  m = load_error(dir / "bare.ckpt", b);
  EXPECT_NE(m.find((dir / "bare.ckpt").string() + "': integrator state: missing"), std::string::npos) << m;
  write_checkpoint(b.particles(), {0.5, 3, "CSPHSIM1\x07"}, dir / "short.ckpt");
  m = load_error(dir / "short.ckpt", b);
  EXPECT_NE(m.find("integrator state: the user data ends (9 bytes) inside the version"), std::string::npos)
      << m;
  EXPECT_TRUE(same_fields(before, b.particles()));
  EXPECT_EQ(load_error(dir / "a.ckpt", a), "no error");

  // read_simulation_checkpoint_extra validates the same way, for any dimension and precision.
  auto extra_error = [](const std::filesystem::path& path) -> std::string {
    try {
      return "no error: '" + read_simulation_checkpoint_extra(path) + "'";
    } catch (const InputError& e) {
      return e.what();
    }
  };
  EXPECT_EQ(extra_error(dir / "3d.ckpt"), "no error: ''");
  EXPECT_EQ(extra_error(dir / "f.ckpt"), "no error: ''");
  m = extra_error(dir / "bare.ckpt");
  EXPECT_NE(m.find((dir / "bare.ckpt").string() + "': integrator state: missing"), std::string::npos) << m;
  m = extra_error(dir / "short.ckpt");
  EXPECT_NE(m.find("integrator state: the user data ends (9 bytes) inside the version"), std::string::npos)
      << m;
  m = extra_error(dir / "nothing.ckpt");
  EXPECT_NE(m.find((dir / "nothing.ckpt").string()), std::string::npos) << m;
}

// A checkpoint whose checksum is right can still hold values no run holds (written by another tool, or
// edited and re-summed): a NaN position once passed restore() and stopped the first step with "internal
// check failed" in the neighbour search (found by fuzz/checkpoint_fuzz.cpp, which re-sums its inputs); a
// level outside 0..max_level would shift by a negative count. Each is refused, naming the particle.
TEST(SimulationCheckpoint, ValuesNoRunHoldsAreRefusedNamingTheParticle) {
  const auto cfg = config<2, double>(Model::Wcsph);
  Simulation<2, double> sim(cfg, block<2, double>(3));
  const auto good = sim.particles();
  const IntegratorState<double> st{0.5, 1e-3, 7, false};
  auto error = [&](const Particles<2, double>& p, const IntegratorState<double>& s) -> std::string {
    try {
      sim.restore(p, s, "checkpoint 'c'");
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  auto p = good;
  p.x[4][1] = std::nan("");
  EXPECT_EQ(error(p, st), "checkpoint 'c': particle 4 has a non-finite position");
  p = good;
  p.mu[8] = -HUGE_VAL;
  EXPECT_EQ(error(p, st), "checkpoint 'c': particle 8 has a non-finite viscosity");
  p = good;
  p.h[2] = 0;
  EXPECT_EQ(error(p, st), "checkpoint 'c': particle 2 has support 0.000000, the scene's is 0.050000");
  p = good;
  for (auto& t : p.tick) t = 100;
  p.tick[3] = 100 + 4096 + 1;  // more than 2^12 ticks (one dt_max) ahead of the others
  EXPECT_EQ(error(p, st),
            "checkpoint 'c': fluid particles' ticks span 100..4197, more than 2^12 (one largest step)");
  p.tick[3] = 100 + 4096;
  EXPECT_EQ(error(p, {0.5, 1e-3, 0, false}), "no error");
  p = good;
  p.level[1] = cfg.time.max_level + 1;
  EXPECT_NE(error(p, st).find("checkpoint 'c': particle 1 has time-step level 13 / tick 0, outside 0..12"),
            std::string::npos);
  p = good;
  p.tick[0] = -1;
  EXPECT_NE(error(p, st).find("particle 0 has time-step level 0 / tick -1"), std::string::npos);
  EXPECT_NE(error(good, {std::nan(""), 1e-3, 7, false}).find("simulated time nan"), std::string::npos);
  EXPECT_NE(error(good, {0.5, -1, 7, false}).find("last step -1.000000 is not a finite number >= 0"),
            std::string::npos);
  // The solver state: one finite entry per particle (or none).
  auto state_error = [&](const SolverState<2, double>& ss) -> std::string {
    try {
      sim.restore(good, st, "checkpoint 'c'", ss);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  SolverState<2, double> ss;
  ss.dfsph_kappa_v.assign(good.size() - 1, 0.0);
  EXPECT_EQ(state_error(ss),
            "checkpoint 'c': holds 8 entries of the solver state 'dfsph_kappa_v' for 9 particles");
  ss.dfsph_kappa_v.assign(good.size(), 0.0);
  ss.dfsph_kappa_v[5] = std::nan("");
  EXPECT_EQ(state_error(ss), "checkpoint 'c': particle 5 has a non-finite dfsph_kappa_v");
  EXPECT_EQ(sim.steps(), 0u) << "untouched on error (the one success above restored step 0)";
  EXPECT_EQ(error(good, st), "no error");
  EXPECT_EQ(sim.steps(), 7u);
}

}  // namespace
}  // namespace cellsph
