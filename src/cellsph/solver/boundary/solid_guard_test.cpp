// No fluid particle ends a step past a solid's first layer of wall particles, half a spacing inside its
// surface (issue 52 item 1): a lone particle thrown at 60 m/s, three spacings a step, at the tank's wall
// (two layers, 0.04 m: without the guard it crosses them in one step), at box, disc, rectangle and mesh
// obstacles, through a wall one spacing thick, at a mesh container's wall, and hit by a moving obstacle and
// a floating body, comes back out on the fluid side with every wall model, and the guard counts it; a tank
// at rest never needs it. Each solid's inside is worked out here from its own geometry, not from the
// guard's grid.
#include "cellsph/solver/boundary/solid_guard.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <utility>

#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

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

// How deep inside the solids under test a position is [m] (<= 0: on the fluid side), at a step of a run.
using Depth2 = std::function<double(const Vec<2, double>&, const Simulation<2, double>&)>;

// Throws the particle with velocity v and checks after every step that it is nowhere deeper than kDepth
// inside the tank's walls or the solid `depth` measures (with a thousandth of a spacing for round-off).
void throw_and_check(const nlohmann::json& j, Vec<2, double> v, const Depth2& depth, int steps = 40) {
  auto s = load_scene<2, double>(j, "lone.json");
  s.particles.v[the_fluid_particle(s.particles)] = v;
  Simulation<2, double> sim(s.solver, s.particles);
  for (int step = 0; step < steps; ++step) {
    sim.step();
    const auto& p = sim.particles();
    const auto x = p.x[the_fluid_particle(p)];
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(x[a], -kDepth) << "step " << step;
      EXPECT_LE(x[a], 1 + kDepth) << "step " << step;
    }
    EXPECT_LE(depth(x, sim), kDepth * 1.001) << "step " << step << ": (" << x[0] << ", " << x[1] << ")";
  }
  EXPECT_GT(sim.wall_corrections(), 0U);
}

// Depth inside the box [lo, hi]: the distance to its nearest face, negative outside.
double box_depth(const Vec<2, double>& x, Vec<2, double> lo, Vec<2, double> hi) {
  return std::min(std::min(x[0] - lo[0], hi[0] - x[0]), std::min(x[1] - lo[1], hi[1] - x[1]));
}

void throw_and_check(const nlohmann::json& j, Vec<2, double> v, Vec<2, double> box_lo,
                     Vec<2, double> box_hi) {
  throw_and_check(j, v, [&](const Vec<2, double>& x, const Simulation<2, double>&) {
    return box_depth(x, box_lo, box_hi);
  });
}

const char* const kWallModels[] = {"akinci", "adami", "dynamic"};

TEST(SolidGuard, ALoneFastParticleStaysInTheTankWithEveryWallModel) {
  for (const std::string model : kWallModels) {
    SCOPED_TRACE(model);
    // Left, then down at 60 m/s: 0.06 m a step, past both wall layers in one.
    throw_and_check(lone_particle(model), {-60, 0}, {2, 2}, {2, 2});
    throw_and_check(lone_particle(model), {0, -60}, {2, 2}, {2, 2});
    throw_and_check(lone_particle(model), {45, 45}, {2, 2}, {2, 2});
  }
}

TEST(SolidGuard, ALoneFastParticleComesBackOutOfABoxObstacle) {
  for (const std::string model : kWallModels) {
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["boundary"]["obstacles"] = nlohmann::json::parse(R"([{"min": [0.2, 0.3], "max": [0.3, 0.7]}])");
    throw_and_check(j, {-60, 0}, {0.2, 0.3}, {0.3, 0.7});
  }
}

TEST(SolidGuard, ALoneFastParticleComesBackOutOfADiscAndARectangle) {
  for (const std::string model : kWallModels) {
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["boundary"]["obstacles"] =
        nlohmann::json::parse(R"([{"sphere": {"center": [0.25, 0.5], "radius": 0.1}}])");
    // Along the axis and off it (the particle meets the disc's side at a slant).
    // The disc's distance is interpolated bilinearly on a grid of one spacing's pitch: off by up to
    // pitch^2 / (8 radius) = 0.0005 m (a fortieth of a spacing) where the circle curves.
    for (const Vec<2, double> v : {Vec<2, double>{-60, 0}, Vec<2, double>{-60, -5}}) {
      throw_and_check(j, v, [](const Vec<2, double>& x, const Simulation<2, double>&) {
        return 0.1 - std::hypot(x[0] - 0.25, x[1] - 0.5) - 0.0005;
      });
    }
    // A cylinder's 2D section: the rectangle [0.2, 0.3] x [0.3, 0.7], its faces from the grid.
    j["boundary"]["obstacles"] = nlohmann::json::parse(
        R"([{"cylinder": {"base": [0.25, 0.3], "axis": [0, 1], "radius": 0.05, "height": 0.4}}])");
    throw_and_check(j, {-60, 0}, {0.2, 0.3}, {0.3, 0.7});
  }
}

// A wall one spacing thick is crossed whole in one step at 60 m/s: the particle is followed along its path.
TEST(SolidGuard, AFastParticleDoesNotCrossAThinWallInOneStep) {
  for (const std::string model : kWallModels) {
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["boundary"]["obstacles"] = nlohmann::json::parse(R"([{"min": [0.4, 0.2], "max": [0.42, 0.8]}])");
    throw_and_check(j, {-60, 0}, [](const Vec<2, double>& x, const Simulation<2, double>&) {
      // Beyond the wall (x < 0.4) counts as deep as the particle went past its far face, plus the wall.
      return x[0] < 0.4 ? 0.02 + (0.4 - x[0]) : box_depth(x, {0.4, 0.2}, {0.42, 0.8});
    });
  }
}

// A box obstacle driven at 30 m/s onto a particle at rest pushes it ahead, in the box's frame.
TEST(SolidGuard, AMovingObstacleDoesNotOvertakeAParticle) {
  for (const std::string model : kWallModels) {
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["boundary"]["obstacles"] = nlohmann::json::parse(
        R"([{"min": [0.1, 0.3], "max": [0.2, 0.7], "motion": {"translate": {"velocity": [30, 0], "end": 0.02}}}])");
    throw_and_check(
        j, {0, 0},
        [](const Vec<2, double>& x, const Simulation<2, double>& sim) {
          const double shift = 30 * std::min(static_cast<double>(sim.time()), 0.02);
          return box_depth(x, {0.1 + shift, 0.3}, {0.2 + shift, 0.7});
        },
        30);
  }
}

// A heavy floating box thrown at 40 m/s onto a particle at rest: it does not swallow it.
TEST(SolidGuard, AFloatingBodyDoesNotSwallowAParticle) {
  for (const std::string model : {"akinci", "adami"}) {  // bodies refuse dynamic walls
    SCOPED_TRACE(model);
    auto j = lone_particle(model);
    j["bodies"] = nlohmann::json::parse(
        R"([{"box": {"min": [0.1, 0.4], "max": [0.3, 0.6]}, "density": 50000, "velocity": [40, 0]}])");
    throw_and_check(
        j, {0, 0},
        [](const Vec<2, double>& x, const Simulation<2, double>& sim) {
          // The box where its particles are now: their bounds, grown by the half spacing they sit inside it.
          const auto& p = sim.particles();
          Vec<2, double> lo{1e9, 1e9}, hi{-1e9, -1e9};
          for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kind[i] == std::uint8_t(ParticleKind::Fluid) || p.x[i][1] < 0.3 || p.x[i][1] > 0.7 ||
                p.x[i][0] < 0.05 || p.x[i][0] > 0.95)
              continue;  // the tank's walls lie outside [0.05, 0.95] x [0.3, 0.7]
            for (int a = 0; a < 2; ++a) {
              lo[a] = std::min(lo[a], p.x[i][a] - kSpacing / 2);
              hi[a] = std::max(hi[a], p.x[i][a] + kSpacing / 2);
            }
          }
          return box_depth(x, lo, hi);
        },
        15);
  }
}

// 3D: a lone particle in oil-glass's glass (a 48-sided cylinder mesh, 0.1 m radius, 0.3 m tall, a
// container) thrown at 60 m/s (3.75 spacings a step) at its side, its bottom and its rim's lid stays inside.
TEST(SolidGuard, ALoneFastParticleStaysInAMeshContainer) {
  std::string source;
  auto j = read_scene_json("oil-glass", source);
  j["fluids"] = nlohmann::json::parse(R"([{"min": [-0.004, 0.096, -0.004], "max": [0.004, 0.104, 0.004]}])");
  j["solver"]["gravity"] = {0, 0, 0};
  j["time"] = nlohmann::json::parse(R"({"stepping": "fixed", "dt": 0.0005})");
  j.erase("initial_pressure");
  const double spacing = j["spacing"].get<double>(), depth = 0.5 * spacing;
  // The mesh's faces lie up to 0.1 (1 - cos(pi / 48)) = 0.0002 m inside the circle through its vertices,
  // and the grid's interpolation is off by up to pitch^2 / (8 radius) = 0.0001 m.
  const double slack = 0.0003;
  for (const Vec<3, double> v :
       {Vec<3, double>{60, 0, 0}, Vec<3, double>{30, -52, 0}, Vec<3, double>{0, 60, 0}}) {
    auto s = load_scene<3, float>(j, source);
    std::size_t fluid = s.particles.size();
    for (std::size_t i = 0; i < s.particles.size(); ++i)
      if (s.particles.kind[i] == std::uint8_t(ParticleKind::Fluid)) fluid = i;
    ASSERT_LT(fluid, s.particles.size());
    for (int a = 0; a < 3; ++a) s.particles.v[fluid][a] = static_cast<float>(v[a]);
    Simulation<3, float> sim(s.solver, s.particles);
    for (int step = 0; step < 30; ++step) {
      sim.step();
      const auto& p = sim.particles();
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != std::uint8_t(ParticleKind::Fluid)) continue;
        const auto x = p.x[i];
        EXPECT_LE(std::hypot(double(x[0]), double(x[2])), 0.1 + depth + slack) << "step " << step;
        EXPECT_GE(double(x[1]), -depth - slack) << "step " << step;
        EXPECT_LE(double(x[1]), 0.3 + depth + slack) << "step " << step;
      }
    }
    EXPECT_GT(sim.wall_corrections(), 0U);
  }
}

// The guard's shapes, frames and path following on the host-emulated device: the CPU's bits and count.
TEST(SolidGuard, TheHostEmulatedDeviceGivesTheCpusBits) {
  auto disc = lone_particle("adami");
  disc["boundary"]["obstacles"] =
      nlohmann::json::parse(R"([{"sphere": {"center": [0.25, 0.5], "radius": 0.1}}])");
  auto thin = lone_particle("adami");
  thin["boundary"]["obstacles"] = nlohmann::json::parse(R"([{"min": [0.4, 0.2], "max": [0.42, 0.8]}])");
  auto moving = lone_particle("adami");
  moving["boundary"]["obstacles"] = nlohmann::json::parse(
      R"([{"min": [0.1, 0.3], "max": [0.2, 0.7], "motion": {"translate": {"velocity": [30, 0], "end": 0.02}}}])");
  auto body = lone_particle("adami");
  body["bodies"] = nlohmann::json::parse(
      R"([{"box": {"min": [0.1, 0.4], "max": [0.3, 0.6]}, "density": 50000, "velocity": [40, 0]}])");
  for (const auto& [j, v] :
       {std::pair{disc, Vec<2, double>{-60, -5}}, std::pair{thin, Vec<2, double>{-60, 0}},
        std::pair{moving, Vec<2, double>{0, 0}}, std::pair{body, Vec<2, double>{0, 0}}}) {
    auto s = load_scene<2, double>(j, "lone.json");
    s.particles.v[the_fluid_particle(s.particles)] = v;
    Simulation<2, double> cpu(s.solver, s.particles), dev(s.solver, s.particles);
    dev.use_backend(Backend::HostDevice);
    for (int step = 0; step < 25; ++step) {
      cpu.step();
      dev.step();
    }
    EXPECT_TRUE(test::same_state(cpu.particles(), dev.particles()));
    EXPECT_GT(cpu.wall_corrections(), 0U);
    EXPECT_EQ(cpu.wall_corrections(), dev.wall_corrections());
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
