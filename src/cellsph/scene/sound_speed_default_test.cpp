// A scene that leaves /solver/eos/stiffness out gets the stiffness of the speed of sound
// c = 10 sqrt(2 g H), H from the fluid's top to the lowest wall (issue 52 item 4). The expected H is
// worked out here from the scene's geometry (lattice sites at (i + 1/2) spacing, wall layers below the
// tank's floor), not read from the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cellsph/scene/scene.hpp"

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
  EXPECT_TRUE(dfsph.derived.empty());
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

}  // namespace
}  // namespace cellsph
