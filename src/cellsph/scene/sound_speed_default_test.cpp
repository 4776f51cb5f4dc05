// A scene that leaves /solver/eos/stiffness out gets the stiffness of the speed of sound
// c = 10 sqrt(2 g H), H from the fluid's top to the lowest wall (issue 52 item 4). The expected H is
// worked out here from the scene's geometry (lattice sites at (i + 1/2) spacing, wall layers below the
// tank's floor), not read from the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>
#include "cellsph/scene/builtin_scenes_test_util.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"
#include "cellsph/solver/solver_test_util.hpp"

namespace cellsph {
namespace {

nlohmann::json tank_without_stiffness() {
  std::string source;
  nlohmann::json j = read_scene_json("hydrostatic-tank", source);
  j["solver"]["eos"].erase("stiffness");
  return j;
}

TEST(SoundSpeedDefault, TankGetsTenTimesTheFallSpeedFromTopToLowestWall) {
  const auto s = load_scene<2, double>(tank_without_stiffness(), "tank.json");
  // Water in [0, 1] x [0, 0.5] at spacing 0.02: the top row at y = 0.49. Two wall layers under the floor
  // y = 0: rows at -0.01 and -0.03.
  const double h = 0.49 + 0.03, c = 10 * std::sqrt(2 * 9.81 * h);
  EXPECT_NEAR(s.solver.eos.sound_speed(1000), c, 1e-9 * c);
  // The ratio equation of state: c^2 = k / rho0.
  EXPECT_NEAR(s.solver.eos.stiffness, 1000 * c * c, 1e-6 * 1000 * c * c);
  ASSERT_EQ(s.derived.size(), 1U);
  EXPECT_EQ(s.derived[0].key, "/solver/eos/stiffness");
  EXPECT_EQ(s.derived[0].value, s.solver.eos.stiffness);
  EXPECT_NE(s.derived[0].why.find("H = 0.52 m"), std::string::npos) << s.derived[0].why;
}

TEST(SoundSpeedDefault, EveryKindOfStateEquationGetsTheSameSpeed) {
  const double c = 10 * std::sqrt(2 * 9.81 * 0.52);
  for (const std::string kind : {"tait", "linear", "ratio", "seventh"}) {
    SCOPED_TRACE(kind);
    auto j = tank_without_stiffness();
    j["solver"]["eos"]["kind"] = kind;
    const auto s = load_scene<2, double>(j, "tank.json");
    EXPECT_NEAR(s.solver.eos.sound_speed(1000), c, 1e-9 * c);
  }
}

TEST(SoundSpeedDefault, AGivenStiffnessAndTheImplicitModelsKeepTheirs) {
  std::string source;
  const auto given = load_scene<2, double>(read_scene_json("hydrostatic-tank", source), source);
  EXPECT_EQ(given.solver.eos.stiffness, 981000);
  EXPECT_TRUE(given.derived.empty());
  const auto dfsph = load_scene<2, double>(read_scene_json("dam-break-2d-dfsph", source), source);
  EXPECT_EQ(dfsph.solver.eos.stiffness, EquationOfState<double>{}.stiffness);
  for (const auto& d : dfsph.derived) EXPECT_NE(d.key, "/solver/eos/stiffness");
}

TEST(SoundSpeedDefault, WithoutGravityTheFixedDefaultIsSaid) {
  auto j = tank_without_stiffness();
  j["solver"]["gravity"] = {0, 0};
  const auto s = load_scene<2, double>(j, "tank.json");
  EXPECT_EQ(s.solver.eos.stiffness, EquationOfState<double>{}.stiffness);
  ASSERT_EQ(s.derived.size(), 1U);
  EXPECT_NE(s.derived[0].why.find("no gravity"), std::string::npos) << s.derived[0].why;
  EXPECT_NE(s.derived[0].why.find("set /solver/eos/stiffness"), std::string::npos) << s.derived[0].why;
}

// The paper's planes are walls too: a floor plane at y = -0.25, under fluid whose top row is at 0.975.
TEST(SoundSpeedDefault, AFloorPlaneIsTheLowestWall) {
  const auto j = nlohmann::json::parse(R"({
    "dimension": 2, "spacing": 0.05,
    "phases": [{"name": "water", "rest_density": 1000}],
    "solver": {"support": 0.1, "eos": {"kind": "tait"}, "gravity": [0, -9.81]},
    "fluids": [{"min": [0, 0], "max": [1, 1]}],
    "boundary": {"planes": [{"normal": [0, 1], "point": [0, -0.25]}]}
  })");
  const auto s = load_scene<2, double>(j, "planes.json");
  const double c = 10 * std::sqrt(2 * 9.81 * (0.975 + 0.25));
  EXPECT_NEAR(s.solver.eos.sound_speed(1000), c, 1e-9 * c);
}

// DFSPH and IISPH scenes with Courant steps get /time/dt_column = 0.7 d / sqrt(g H) when they leave it out
// (scene/sound_speed_default.cpp; docs/physics.md "Model 3"): the longest step a resting column H deep holds
// at spacing d, H from the fluid's top to the lowest wall as for the stiffness. The expected values are
// worked out here from the scenes' geometry (lattice sites at (i + 1/2) spacing, wall layers under the
// floor), not read from the code under test. The case it is for is dam-break-2d-dfsph at half its spacing
// (issue 52 item 3's fine end): at the scene's dt_max of 5 ms its 200-row column compressed its bottom
// corner 17% by t = 0.03 s and threw particles at 19 m/s (IISPH: 5.8 km/s at 0.05 s).

nlohmann::json dfsph_dam_break(double f, const char* model = "dfsph") {
  std::string src;
  auto j = test::scaled_scene(read_scene_json("dam-break-2d-dfsph", src), f);
  if (std::string(model) == "iisph") {
    j["solver"]["model"] = "iisph";
    j["solver"].erase("dfsph");
  }
  return j;
}

const DerivedSetting* derived(const Scene<2, double>& s, const std::string& key) {
  for (const auto& d : s.derived)
    if (d.key == key) return &d;
  return nullptr;
}

// Water in [0, 1] x [0, 2]: its top row at 2 - d/2; two wall layers under the floor y = 0, the lower at
// -3 d / 2. So H = 2 + d.
TEST(ColumnStepDefault, DfsphAndIisphScenesGetItFromTheFluidsHeight) {
  for (const double f : {1.0, 0.5}) {
    for (const char* model : {"dfsph", "iisph"}) {
      SCOPED_TRACE(std::string(model) + " at " + std::to_string(f) + " x the spacing");
      const double d = 0.02 * f, H = 2 + d, expected = 0.7 * d / std::sqrt(9.81 * H);
      const auto s = load_scene<2, double>(dfsph_dam_break(f, model), "dam.json");
      EXPECT_NEAR(s.solver.time.dt_column, expected, 1e-12 * expected);
      const DerivedSetting* said = derived(s, "/time/dt_column");
      ASSERT_NE(said, nullptr);
      EXPECT_EQ(said->value, s.solver.time.dt_column);
      EXPECT_NE(said->why.find("0.7 d / sqrt(g H)"), std::string::npos) << said->why;
    }
  }
}

// Volume-map walls make no wall particles: the lowest wall is the tank's floor y = 0 itself (the guard's
// tank), so H = 2 - d/2 from the top row. Without it no bound was derived for such a scene.
TEST(ColumnStepDefault, VolumeMapWallsTakeTheTanksFloor) {
  for (const double f : {1.0, 0.5}) {
    SCOPED_TRACE(std::to_string(f) + " x the spacing");
    auto j = dfsph_dam_break(f);
    j["boundary"]["model"] = "volume-map";
    const double d = 0.02 * f, H = 2 - d / 2, expected = 0.7 * d / std::sqrt(9.81 * H);
    const auto s = load_scene<2, double>(j, "dam.json");
    EXPECT_EQ(s.particles.size(), std::size_t(std::lround(2 / (d * d))));  // fluid only
    EXPECT_NEAR(s.solver.time.dt_column, expected, 1e-12 * expected);
    const DerivedSetting* said = derived(s, "/time/dt_column");
    ASSERT_NE(said, nullptr);
    EXPECT_EQ(said->value, s.solver.time.dt_column);
  }
}

// A scene's own dt_column is kept (0: no bound), fixed steps and the explicit models get none.
TEST(ColumnStepDefault, GivenFixedStepsAndExplicitModelsKeepTheirs) {
  auto given = dfsph_dam_break(1);
  given["time"]["dt_column"] = 0;
  const auto a = load_scene<2, double>(given, "dam.json");
  EXPECT_EQ(a.solver.time.dt_column, 0.0);
  EXPECT_EQ(derived(a, "/time/dt_column"), nullptr);
  auto fixed = dfsph_dam_break(1);
  fixed["time"]["stepping"] = "fixed";
  fixed["time"]["dt"] = 0.001;
  const auto b = load_scene<2, double>(fixed, "dam.json");
  EXPECT_EQ(b.solver.time.dt_column, 0.0);
  EXPECT_EQ(derived(b, "/time/dt_column"), nullptr);
  std::string src;
  const auto c = load_scene<2, double>(read_scene_json("dam-break-2d", src), src);
  EXPECT_EQ(c.solver.time.dt_column, 0.0);
  EXPECT_EQ(derived(c, "/time/dt_column"), nullptr);
  auto bad = dfsph_dam_break(1);
  bad["time"]["dt_column"] = -1;
  try {
    (void)load_scene<2, double>(bad, "dam.json");
    ADD_FAILURE() << "accepted dt_column -1";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dt_column"), std::string::npos) << e.what();
  }
}

// dam-break-2d-dfsph at half its spacing, DFSPH and IISPH, over 0.2 s: the first step is the derived bound
// (under the scene's dt_max), and no particle is faster than the free fall from the column's top,
// sqrt(2 g 2 m) = 6.3 m/s. With the bound taken away (dt_column 0) the same runs pass that speed within
// 0.05 s (checked by hand: 18.8 m/s at 0.035 s with DFSPH).
TEST(ColumnStepDefault, DamBreakAtHalfItsSpacingStaysBelowTheFreeFallSpeed) {
  for (const char* model : {"dfsph", "iisph"}) {
    SCOPED_TRACE(model);
    const auto scene = load_scene<2, double>(dfsph_dam_break(0.5, model), "dam.json");
    const double free_fall = std::sqrt(2 * 9.81 * 2.0);
    Simulation<2, double> sim(scene.solver, scene.particles);
    sim.step();
    EXPECT_EQ(sim.last_dt(), scene.solver.time.dt_column);
    EXPECT_LT(scene.solver.time.dt_column, scene.solver.time.dt_max);
    double v_max = 0;
    while (sim.time() < 0.2) {
      sim.step();
      v_max = std::max(v_max, test::max_speed(sim.particles()));
      ASSERT_LT(v_max, free_fall) << "step " << sim.steps() << ", t = " << sim.time() << " s";
    }
  }
}

}  // namespace
}  // namespace cellsph
