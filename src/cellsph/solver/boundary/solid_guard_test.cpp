// No fluid particle ends a step past a solid's first layer of wall particles, half a spacing inside its
// surface (issue 52 item 1): a lone particle thrown at 60 m/s, three spacings a step, at the tank's wall
// (two layers, 0.04 m: without the guard it crosses them in one step) and at a box obstacle comes back
// out on the fluid side with every wall model, and the guard counts it; a tank at rest never needs it.
#include "cellsph/solver/boundary/solid_guard.hpp"

#include <gtest/gtest.h>

#include <string>

#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

constexpr double kSpacing = 0.02, kDepth = 0.5 * kSpacing;  // the first layer of wall particles

// One fluid particle at (0.5, 0.5) in a closed 1 x 1 m tank, no gravity, fixed steps of 1 ms.
nlohmann::json lone_particle(const std::string& wall_model) {
  auto j = nlohmann::json::parse(R"({
    "dimension": 2, "spacing": 0.02,
    "phases": [{"name": "water", "rest_density": 1000}],
    "solver": {"model": "wcsph", "support": 0.04, "density_kernel": "cubic", "pressure_kernel": "cubic",
               "eos": {"kind": "ratio", "stiffness": 1e5, "clamp_negative": true}, "gravity": [0, 0]},
    "time": {"stepping": "fixed", "dt": 0.001},
    "fluids": [{"min": [0.49, 0.49], "max": [0.51, 0.51]}],
    "boundary": {"walls": {"min": [0, 0], "max": [1, 1], "layers": 2, "open_top": false}}
  })");
  j["boundary"]["model"] = wall_model;
  return j;
}

std::size_t the_fluid_particle(const Particles<2, double>& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == std::uint8_t(ParticleKind::Fluid)) return i;
  ADD_FAILURE() << "no fluid particle";
  return 0;
}

// Throws the particle with velocity v and checks after every step that it is nowhere deeper than kDepth
// inside the tank's walls or the box [box_lo, box_hi].
void throw_and_check(const nlohmann::json& j, Vec<2, double> v, Vec<2, double> box_lo,
                     Vec<2, double> box_hi) {
  auto s = load_scene<2, double>(j, "lone.json");
  s.particles.v[the_fluid_particle(s.particles)] = v;
  Simulation<2, double> sim(s.solver, s.particles);
  for (int step = 0; step < 40; ++step) {
    sim.step();
    const auto& p = sim.particles();
    const auto x = p.x[the_fluid_particle(p)];
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(x[a], -kDepth) << "step " << step;
      EXPECT_LE(x[a], 1 + kDepth) << "step " << step;
    }
    const bool inside = x[0] > box_lo[0] + kDepth && x[0] < box_hi[0] - kDepth && x[1] > box_lo[1] + kDepth &&
                        x[1] < box_hi[1] - kDepth;
    EXPECT_FALSE(inside) << "step " << step << ": (" << x[0] << ", " << x[1] << ")";
  }
  EXPECT_GT(sim.wall_corrections(), 0U);
}

TEST(SolidGuard, ALoneFastParticleStaysInTheTankWithEveryWallModel) {
  for (const std::string model : {"akinci", "adami", "dynamic"}) {
    SCOPED_TRACE(model);
    // Left, then down at 60 m/s: 0.06 m a step, past both wall layers in one.
    throw_and_check(lone_particle(model), {-60, 0}, {2, 2}, {2, 2});
    throw_and_check(lone_particle(model), {0, -60}, {2, 2}, {2, 2});
    throw_and_check(lone_particle(model), {45, 45}, {2, 2}, {2, 2});
  }
}

TEST(SolidGuard, ALoneFastParticleComesBackOutOfABoxObstacle) {
  for (const std::string model : {"akinci", "adami", "dynamic"}) {
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["boundary"]["obstacles"] = nlohmann::json::parse(R"([{"min": [0.2, 0.3], "max": [0.3, 0.7]}])");
    throw_and_check(j, {-60, 0}, {0.2, 0.3}, {0.3, 0.7});
  }
}

// A tank at rest never needs the guard: nothing is put back, so nothing is changed.
TEST(SolidGuard, ATankAtRestNeedsNoCorrection) {
  std::string source;
  const auto s = load_scene<2, double>(read_scene_json("hydrostatic-tank", source), source);
  ASSERT_TRUE(s.solver.guard.container);
  Simulation<2, double> sim(s.solver, s.particles);
  for (int step = 0; step < 300; ++step) sim.step();
  EXPECT_EQ(sim.wall_corrections(), 0U);
}

}  // namespace
}  // namespace cellsph
