// Under-resolved geometry is said when a scene loads (issue 52 item 5): gaps under two spacings between
// obstacles (boxes and shapes) or an obstacle and the tank's walls, obstacles thinner than the kernel
// support. The gaps and thicknesses are set here by hand.
#include <gtest/gtest.h>

#include <string>

#include "cellsph/scene/scene.hpp"

namespace cellsph {
namespace {

// A 1 x 1 m tank at spacing 0.02 and support 0.04, with the obstacles given.
std::vector<std::string> warnings_of(const nlohmann::json& obstacles) {
  auto j = nlohmann::json::parse(R"({
    "dimension": 2, "spacing": 0.02,
    "phases": [{"name": "water", "rest_density": 1000}],
    "solver": {"model": "wcsph", "support": 0.04, "eos": {"stiffness": 1e5}},
    "fluids": [{"min": [0, 0.6], "max": [1, 0.8]}],
    "boundary": {"model": "adami", "walls": {"min": [0, 0], "max": [1, 1], "layers": 2}}
  })");
  j["boundary"]["obstacles"] = obstacles;
  return load_scene<2, double>(j, "gaps.json").warnings;
}

nlohmann::json box(double x0, double y0, double x1, double y1) {
  return {{"min", {x0, y0}}, {"max", {x1, y1}}};
}

TEST(GeometryWarnings, WellResolvedGeometryIsQuiet) {
  // Gaps of 2.5 spacings between the two blocks and to the right wall; both 0.1 m thick.
  EXPECT_TRUE(warnings_of(nlohmann::json::array({box(0.2, 0, 0.3, 0.3), box(0.35, 0, 0.45, 0.3)})).empty());
  EXPECT_TRUE(warnings_of(nlohmann::json::array({box(0.85, 0, 0.95, 0.3)})).empty());
}

TEST(GeometryWarnings, ANarrowGapBetweenObstaclesNamesBoth) {
  const auto w = warnings_of(nlohmann::json::array({box(0.2, 0, 0.3, 0.3), box(0.33, 0, 0.43, 0.3)}));
  ASSERT_EQ(w.size(), 1U);
  EXPECT_EQ(w[0].rfind(
                "/boundary/obstacles/0 and /boundary/obstacles/1: a gap of 0.03 m along x (1.5 spacings)", 0),
            0U)
      << w[0];
  EXPECT_NE(w[0].find("at most 0.015 m"), std::string::npos) << w[0];
}

TEST(GeometryWarnings, ANarrowGapToTheWallsNamesTheWalls) {
  const auto w = warnings_of(nlohmann::json::array({box(0.8, 0, 0.97, 0.3)}));
  ASSERT_EQ(w.size(), 1U);
  EXPECT_EQ(w[0].rfind("/boundary/obstacles/0 and /boundary/walls: a gap of 0.03 m along x", 0), 0U) << w[0];
}

// A fluid block thinner than the support along y (0.03 m, under 0.04) is said, named by its index in
// /fluids (the shaped volume before it counts); one of 0.04 m is not.
TEST(GeometryWarnings, AFluidBlockThinnerThanTheSupport) {
  auto j = nlohmann::json::parse(R"({
    "dimension": 2, "spacing": 0.01,
    "phases": [{"name": "water", "rest_density": 1000}],
    "solver": {"model": "wcsph", "support": 0.04, "eos": {"stiffness": 1e5}},
    "fluids": [{"sphere": {"center": [0.5, 0.8], "radius": 0.1}}, {"min": [0, 0], "max": [1, 0.03]},
               {"min": [0, 0.5], "max": [1, 0.54]}],
    "boundary": {"model": "adami", "walls": {"min": [0, 0], "max": [1, 1], "layers": 2}}
  })");
  const auto w = load_scene<2, double>(j, "film.json").warnings;
  ASSERT_EQ(w.size(), 1U);
  EXPECT_EQ(w[0].rfind("/fluids/1: 0.03 m thick along y, less than the kernel support 0.04 m", 0), 0U)
      << w[0];
}

TEST(GeometryWarnings, AnObstacleThinnerThanTheSupport) {
  // 0.03 m thick along x (1.5 spacings, under the 0.04 m support); 0.3 m along y.
  const auto w = warnings_of(nlohmann::json::array({box(0.5, 0, 0.53, 0.3)}));
  ASSERT_EQ(w.size(), 1U);
  EXPECT_EQ(
      w[0].rfind("/boundary/obstacles/0: 0.03 m thick along x, thinner than the kernel support 0.04 m", 0),
      0U)
      << w[0];
}

nlohmann::json disc(double x, double y, double r) {
  return {{"sphere", {{"center", {x, y}}, {"radius", r}}}};
}

TEST(GeometryWarnings, ShapesWellApartOrTouchingAreQuiet) {
  // A disc 2.5 spacings above the floor; one resting on it (touching); one on the floor beside a box
  // obstacle 3 spacings away.
  EXPECT_TRUE(warnings_of(nlohmann::json::array({disc(0.5, 0.15, 0.1)})).empty());
  EXPECT_TRUE(warnings_of(nlohmann::json::array({disc(0.5, 0.1, 0.1)})).empty());
  EXPECT_TRUE(warnings_of(nlohmann::json::array({disc(0.5, 0.1, 0.1), box(0.66, 0, 0.8, 0.3)})).empty());
}

TEST(GeometryWarnings, ANarrowGapUnderADiscNamesTheDiscAndTheWalls) {
  // The disc's lowest point 0.03 m (1.5 spacings) above the floor.
  const auto w = warnings_of(nlohmann::json::array({disc(0.5, 0.13, 0.1)}));
  ASSERT_EQ(w.size(), 1U);
  EXPECT_EQ(w[0].rfind("/boundary/obstacles/0 and /boundary/walls: a gap of about 0.03 m (1.5 spacings)", 0),
            0U)
      << w[0];
}

TEST(GeometryWarnings, ANarrowGapBetweenShapesAndABoxNamesBoth) {
  // Two discs 0.025 m apart (1.25 spacings); the second 0.03 m from a box obstacle's face.
  const auto w = warnings_of(
      nlohmann::json::array({disc(0.3, 0.35, 0.1), disc(0.525, 0.35, 0.1), box(0.655, 0.2, 0.75, 0.5)}));
  ASSERT_EQ(w.size(), 2U);
  EXPECT_EQ(w[0].rfind("/boundary/obstacles/0 and /boundary/obstacles/1: a gap of about 0.025 m", 0), 0U)
      << w[0];
  EXPECT_EQ(w[1].rfind("/boundary/obstacles/1 and /boundary/obstacles/2: a gap of about 0.03 m", 0), 0U)
      << w[1];
}

TEST(GeometryWarnings, AThinShapeIsSaid) {
  // A 2D cylinder's section 0.03 m wide (under the 0.04 m support), 0.3 m tall: at most 0.03 m plus the
  // half-spacing lattice's 0.01 m.
  const auto w = warnings_of(nlohmann::json::parse(
      R"([{"cylinder": {"base": [0.5, 0.3], "axis": [0, 1], "radius": 0.015, "height": 0.3}}])"));
  ASSERT_EQ(w.size(), 1U);
  EXPECT_NE(w[0].find("/boundary/obstacles/0: at most 0.0"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("thinner than the kernel support 0.04 m"), std::string::npos) << w[0];
}

}  // namespace
}  // namespace cellsph
