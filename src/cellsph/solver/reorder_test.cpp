// Reordering the particle arrays into cell order (config reorder_every) is a memory-layout change only:
// the physics per particle id must match a run that never reorders (up to the summation order), and
// the guarantees of the solver (same bits for any neighbour method, thread count, resume) must hold
// with it. The cell order itself is checked against an independent Z-order comparison.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/solver/cell_order.hpp"
#include "cellsph/solver/initial.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

using V2 = Vec<2, double>;

using test::same_state;

// A 2D dam break (WCSPH as the scenes set it up): a 1 x 2 column in a 4 x 3 tank of boundary particles.
// The column collapses and spreads, so particles travel far from their input neighbours.
SolverConfig<2, double> dam_config(double s, std::uint32_t reorder_every) {
  SolverConfig<2, double> cfg = test::wcsph_water(s, 10 * std::sqrt(2 * 9.81 * 2));
  cfg.reorder_every = reorder_every;
  return cfg;
}

Particles<2, double> dam_particles(double s) {
  Particles<2, double> p;
  add_block<2, double>(p, V2{{0, 0}}, V2{{1, 2}}, s, 0);
  add_box_walls<2, double>(p, V2{{0, 0}}, V2{{4, 3}}, s, 2, true, 0, 1000 * s * s);
  return p;
}

// The particles in id order (the writers' order), for comparing runs whose internal orders differ.
template <int Dim, class Real>
Particles<Dim, Real> by_id(const Particles<Dim, Real>& p) {
  Particles<Dim, Real> out;
  std::vector<std::uint32_t> from;
  copy_in_id_order(p, out, from);
  return out;
}

bool is_permutation_of_iota(std::vector<std::uint32_t> id) {
  std::sort(id.begin(), id.end());
  for (std::size_t k = 0; k < id.size(); ++k)
    if (id[k] != k) return false;
  return true;
}

// The Z-order key against its definition, bit by bit: bit b of coordinate a is bit Dim * b + a of the key
// (64 / Dim bits a coordinate, higher bits ignored).
template <int Dim>
std::uint64_t morton_by_definition(const std::uint64_t (&c)[Dim]) {
  std::uint64_t key = 0;
  for (int b = 0; b < 64 / Dim; ++b)
    for (int a = 0; a < Dim; ++a) key |= ((c[a] >> b) & 1u) << (b * Dim + a);
  return key;
}

TEST(Reorder, MortonKeyInterleavesTheBits) {
  std::mt19937_64 rng(77);
  for (int t = 0; t < 100000; ++t) {
    const int shift = t % 64;  // small and large coordinates, bits above the key's share included
    const std::uint64_t c2[2] = {rng() >> shift, rng() >> (63 - shift)};
    const std::uint64_t c3[3] = {rng() >> shift, rng() >> (t % 40), rng() >> (63 - shift)};
    ASSERT_EQ(morton_key<2>(c2), morton_by_definition<2>(c2)) << c2[0] << " " << c2[1];
    ASSERT_EQ(morton_key<3>(c3), morton_by_definition<3>(c3)) << c3[0] << " " << c3[1] << " " << c3[2];
  }
  const std::uint64_t ones3[3] = {0x1fffff, 0, 0};
  EXPECT_EQ(morton_key<3>(ones3), 0x1249249249249249ULL);
}

TEST(Reorder, SamePhysicsPerIdAsNoReorder) {
  ScopedThreads one(1);  // thread independence is tested below
  const double s = 0.1;
  // Two phases of different rest density (the right half of the column 10% denser), so that a
  // per-particle array of the solver (rest density) left unpermuted would show.
  auto run = [&](std::uint32_t every) {
    auto cfg = dam_config(s, every);
    cfg.phases.push_back(cfg.phases[0]);
    cfg.phases[1].rest_density = 1100;
    cfg.phases[1].mass = 1100 * s * s;
    auto p = dam_particles(s);
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == 0 && p.x[i][0] > 0.5) p.phase[i] = 1;
    Simulation<2, double> sim(cfg, std::move(p));
    for (int k = 0; k < 400; ++k) sim.step();
    return sim;
  };
  const auto off = run(0);
  const auto on = run(10);
  EXPECT_EQ(off.timings().reorders, 0u);
  EXPECT_EQ(on.timings().reorders, 40u);
  EXPECT_TRUE(is_permutation_of_iota(on.particles().id));
  // The reorders did move particles: the internal order is no longer the input order.
  EXPECT_FALSE(in_id_order(on.particles()));
  EXPECT_TRUE(in_id_order(off.particles()));
  // Same physics per id. The flow is under way (the front has moved), and only the summation order
  // differs (last bits, grown over 400 steps of a splashing flow), so positions agree to a tiny
  // fraction of the spacing while a particle mixed up with another would be off by a spacing.
  const auto a = by_id(off.particles()), b = by_id(on.particles());
  ASSERT_EQ(a.size(), b.size());
  double front = 0, worst_x = 0, worst_v = 0, vmax = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.kind[k], b.kind[k]);
    EXPECT_EQ(a.m[k], b.m[k]);
    if (a.kind[k] != 0) {
      EXPECT_EQ(a.x[k], b.x[k]);  // walls never move
      continue;
    }
    front = std::max(front, a.x[k][0]);
    worst_x = std::max(worst_x, norm(a.x[k] - b.x[k]));
    worst_v = std::max(worst_v, norm(a.v[k] - b.v[k]));
    vmax = std::max(vmax, norm(a.v[k]));
  }
  EXPECT_GT(front, 1.2);  // the column has collapsed
  EXPECT_LT(worst_x, 1e-6 * s) << "front " << front;
  EXPECT_LT(worst_v, 1e-6 * vmax);
}

// Z-order comparison without interleaving bits (the most significant differing bit decides): an
// implementation independent of the solver's Morton key. On a tie of the differing bit the last axis
// decides (its bit is the more significant in the solver's interleave).
bool z_less(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  std::size_t dim = a.size() - 1;
  std::uint64_t best = 0;
  for (std::size_t d = a.size(); d-- > 0;) {
    const std::uint64_t x = a[d] ^ b[d];
    if (best < x && best < (best ^ x)) {
      dim = d;
      best = x;
    }
  }
  return a[dim] < b[dim];
}

// After a reorder consecutive particles of a kind are in Z-order of cells of size h counted from the
// lowest corner of that kind, equal cells by id.
void expect_cell_order(const Particles<2, double>& p, const std::vector<std::size_t>& slots, double h) {
  V2 lo = p.x[slots[0]];
  for (auto i : slots)
    for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], p.x[i][a]);
  // Times 1/h as the solver computes it: wall particles sit exactly on cell faces (x - lo = k h/2), where
  // dividing by h could round to the other side.
  const double inv = 1 / h;
  auto cell = [&](std::size_t i) {
    return std::vector<std::uint64_t>{static_cast<std::uint64_t>(std::floor((p.x[i][0] - lo[0]) * inv)),
                                      static_cast<std::uint64_t>(std::floor((p.x[i][1] - lo[1]) * inv))};
  };
  std::size_t bad = 0;
  for (std::size_t k = 1; k < slots.size(); ++k) {
    const auto a = cell(slots[k - 1]), b = cell(slots[k]);
    const bool ok = a == b ? p.id[slots[k - 1]] < p.id[slots[k]] : z_less(a, b);
    if (!ok) ++bad;
  }
  EXPECT_EQ(bad, 0u);
}

TEST(Reorder, ArraysAreInCellOrderAfterAReorder) {
  ScopedThreads one(1);
  const double s = 0.1;
  auto cfg = dam_config(s, 5);
  // A jittered block (positions away from cell faces), so that a step of 1e-9 s cannot move a
  // particle into another cell: the order checked after the step is the one the reorder made.
  Particles<2, double> p = dam_particles(s);
  std::mt19937 gen(4);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == 0) p.x[i] += V2{{u(gen), u(gen)}} * s;
  // Input order shuffled: the reorder has work to do.
  std::vector<std::size_t> perm(p.size());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), gen);
  Particles<2, double> q;
  q.resize(p.size());
  for (std::size_t k = 0; k < perm.size(); ++k) {
    q.x[k] = p.x[perm[k]];
    q.phase[k] = p.phase[perm[k]];
    q.kind[k] = p.kind[perm[k]];
    q.m[k] = p.m[perm[k]];
  }
  cfg.time.mode = TimeStepping::Fixed;
  cfg.time.dt = 1e-9;
  Simulation<2, double> sim(cfg, q);
  std::vector<std::size_t> fluid, walls;
  for (std::size_t i = 0; i < q.size(); ++i) (q.kind[i] == 0 ? fluid : walls).push_back(i);
  // Boundary particles: sorted once at construction; kinds keep their slots.
  EXPECT_EQ(sim.particles().kind, q.kind);
  {
    SCOPED_TRACE("walls");
    expect_cell_order(sim.particles(), walls, cfg.support);
  }
  sim.step();  // reorders first (step 0)
  EXPECT_EQ(sim.timings().reorders, 1u);
  EXPECT_EQ(sim.particles().kind, q.kind);
  {
    SCOPED_TRACE("fluid");
    expect_cell_order(sim.particles(), fluid, cfg.support);
  }
  EXPECT_TRUE(is_permutation_of_iota(sim.particles().id));
  // Each id still carries its own input: the input position of particle id k was q.x[k].
  for (std::size_t i = 0; i < q.size(); ++i)
    EXPECT_LT(norm(sim.particles().x[i] - q.x[sim.particles().id[i]]), 1e-6) << i;
}

// With reordering on, the neighbour method and the thread count still change no bit.
TEST(Reorder, MethodsAndThreadCountsGiveTheSameBits) {
  const double s = 0.1;
  std::vector<Particles<2, double>> runs;
  for (Method m : kAllMethods) {
    ScopedThreads one(1);
    auto cfg = dam_config(s, 7);
    cfg.search.method = m;
    Simulation<2, double> sim(cfg, dam_particles(s));
    for (int k = 0; k < 120; ++k) sim.step();
    EXPECT_EQ(sim.timings().reorders, 18u);
    runs.push_back(sim.particles());
  }
  {
    ScopedThreads two(2);
    Simulation<2, double> sim(dam_config(s, 7), dam_particles(s));
    for (int k = 0; k < 120; ++k) sim.step();
    runs.push_back(sim.particles());
  }
  EXPECT_FALSE(in_id_order(runs[0]));
  for (std::size_t r = 1; r < runs.size(); ++r) EXPECT_TRUE(same_state(runs[0], runs[r])) << r;
}

// 3D, single precision (the other Morton key): the methods agree bit for bit and the physics per id
// matches a run without reordering.
TEST(Reorder, ThreeDimensionsFloat) {
  using V3 = Vec<3, float>;
  const float s = 0.1f, rho0 = 1000;
  auto make = [&](Method m, std::uint32_t every) {
    SolverConfig<3, float> cfg;
    cfg.model = Model::PaperMultiphase;
    cfg.search.method = m;
    cfg.support = 2 * s;
    cfg.phases[0].mass = rho0 * s * s * s;
    cfg.phases[0].viscosity = 0.5f;
    cfg.eos.stiffness = 200;
    cfg.time.dt = 1e-3f;
    cfg.reorder_every = every;
    Particles<3, float> p;
    add_block<3, float>(p, V3{{0, 0, 0}}, V3{{0.5f, 0.5f, 1.0f}}, s, 0);
    add_box_walls<3, float>(p, V3{{0, 0, 0}}, V3{{1.0f, 0.6f, 1.2f}}, s, 2, true, 0, rho0 * s * s * s);
    Simulation<3, float> sim(cfg, std::move(p));
    for (int k = 0; k < 60; ++k) sim.step();
    return by_id(sim.particles());
  };
  ScopedThreads one(1);
  const auto cell = make(Method::CellIndex, 4), tree = make(Method::KdTree, 4),
             off = make(Method::CellIndex, 0);
  EXPECT_TRUE(same_state(cell, tree));
  float worst = 0, moved = 0;
  for (std::size_t k = 0; k < off.size(); ++k) {
    worst = std::max(worst, norm(cell.x[k] - off.x[k]));
    moved = std::max(moved, norm(off.v[k]));
  }
  EXPECT_GT(moved, 0.1f);
  EXPECT_LT(worst, 1e-3f * s);
}

// A checkpoint holds the permuted order, the ids and the step count that drives the schedule: resuming
// from one taken between two reorders, or just before a reorder is due, gives the same bits.
TEST(Reorder, ResumeBetweenAndAcrossReordersIsBitIdentical) {
  ScopedThreads one(1);
  const double s = 0.1;
  const auto cfg = dam_config(s, 10);
  for (int at : {25, 30}) {
    Simulation<2, double> full(cfg, dam_particles(s));
    for (int k = 0; k < at; ++k) full.step();
    const auto saved = full.particles();
    const auto state = full.integrator_state();
    for (int k = at; k < 60; ++k) full.step();
    Simulation<2, double> resumed(cfg, dam_particles(s));
    resumed.restore(saved, state, "test");
    for (int k = at; k < 60; ++k) resumed.step();
    EXPECT_TRUE(same_state(full.particles(), resumed.particles())) << "checkpoint at step " << at;
    EXPECT_EQ(full.time(), resumed.time());
    EXPECT_EQ(resumed.timings().reorders, 3u);  // before steps 31, 41, 51 (steps() = 30, 40, 50)
  }
}

// Per-particle steps reorder where every particle is due (multiples of reorder_every * dt_max); the
// physics per id matches a run without reordering, and a resume is bit for bit.
TEST(Reorder, PerParticleStepsSamePhysicsPerIdAndResume) {
  ScopedThreads one(1);
  auto cfg = SolverConfig<2, double>{};
  cfg.search.method = Method::CellIndex;
  cfg.support = 0.05;
  cfg.phases[0].mass = 1000 * 0.02 * 0.02;
  cfg.phases[0].viscosity = 1;
  cfg.eos.stiffness = 2000;
  cfg.time.mode = TimeStepping::PerParticle;
  cfg.time.dt_max = 2e-3;
  cfg.time.max_level = 8;
  auto blob = [] {
    Particles<2, double> p;
    add_block<2, double>(p, V2{{0, 0}}, V2{{0.24, 0.24}}, 0.02, 0);
    std::mt19937 gen(9);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = V2{{u(gen), u(gen)}};
    return p;
  };
  auto off_cfg = cfg, on_cfg = cfg;
  off_cfg.reorder_every = 0;
  on_cfg.reorder_every = 1;
  Simulation<2, double> off(off_cfg, blob()), on(on_cfg, blob());
  off.run_until(0.03);
  on.run_until(0.03);
  EXPECT_EQ(off.steps(), on.steps());
  EXPECT_GE(on.timings().reorders, 14u);  // one per dt_max
  const auto a = by_id(off.particles()), b = by_id(on.particles());
  double worst = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.level[k], b.level[k]) << k;
    worst = std::max(worst, norm(a.x[k] - b.x[k]));
  }
  EXPECT_LT(worst, 1e-9);

  Simulation<2, double> full(on_cfg, blob());
  for (int k = 0; k < 40; ++k) full.step();
  const auto saved = full.particles();
  const auto state = full.integrator_state();
  for (int k = 0; k < 40; ++k) full.step();
  Simulation<2, double> resumed(on_cfg, blob());
  resumed.restore(saved, state, "test");
  for (int k = 0; k < 40; ++k) resumed.step();
  EXPECT_TRUE(same_state(full.particles(), resumed.particles()));
}

TEST(Reorder, IdsMustBeAPermutation) {
  const double s = 0.1;
  auto p = dam_particles(s);
  for (std::size_t i = 0; i < p.size(); ++i) p.id[i] = static_cast<std::uint32_t>(p.size() - 1 - i);
  // Given ids are kept (and travel with their particles).
  Simulation<2, double> ok(dam_config(s, 3), p);
  EXPECT_EQ(by_id(ok.particles()).x[p.size() - 1], p.x[0]);
  p.id[5] = p.id[6];
  try {
    Simulation<2, double> bad(dam_config(s, 3), p);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has id"), std::string::npos) << e.what();
  }
  auto restored = ok.particles();
  restored.id[0] = static_cast<std::uint32_t>(restored.size());
  try {
    ok.restore(restored, ok.integrator_state(), "file.ckpt");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("file.ckpt: particle 0 has id"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cellsph
