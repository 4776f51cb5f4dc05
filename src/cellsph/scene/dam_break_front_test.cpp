// The built-in dam-break-2d scene (Koshizuka & Oka 1996: a 1 m x 2 m water column in a 4 m tank),
// coarsened to 0.1 m, against the published surge front. Its set-up is the scene file's: WCSPH, cubic
// kernels, c = 10 sqrt(2 g H), water's viscosity 0.001 Pa s and Monaghan's artificial viscosity alpha = 0.01
// (which scales with h by itself), no-slip walls, a hydrostatic start; both wall models. And Martin &
// Moyce's residual column height at the back wall, with the count of particles clinging to it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/probes/probes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

class DamBreakFront : public ::testing::TestWithParam<std::string> {};

// Martin & Moyce's residual column height at the back wall (data/validation/martin_moyce_1952.txt):
// table [B] (a square column, n^2 = 1: h(x = 0)/a against t sqrt(g / a)) and the residual table of [A]
// (n^2 = 2, the scene's 1 m x 2 m column: h / (2a) against t sqrt(g / a)). A wall that holds the water
// (the former 6.26 Pa s written as a viscosity, no-slip: 0.185 off table [A] at 0.1 m, 0.118 off [B] at
// 0.05 m) keeps the column high at the wall; one that lets
// particles cling leaves a trail above the surface. Returns table `index` (1: the front, 2: the residual
// height) of section "[A]" or "[B]" as pairs of numbers.
std::vector<std::pair<double, double>> martin_moyce(const std::string& table, int index = 2) {
  std::ifstream in(std::string(CELLSPH_SOURCE_DIR) + "/data/validation/martin_moyce_1952.txt");
  std::vector<std::pair<double, double>> out;
  std::string section;
  int tables = 0;  // tables seen in the section: the front, then the residual height
  bool numbers = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# [", 0) == 0) {
      section = line.substr(2, 3);
      tables = 0;
      numbers = false;
      continue;
    }
    if (line.empty() || line[0] == '#') {
      numbers = false;
      continue;
    }
    if (!numbers) ++tables;
    numbers = true;
    if (section == table && tables == index) {
      std::istringstream ls(line);
      double tau = 0, h = 0;
      if (ls >> tau >> h) out.emplace_back(tau, h);
    }
  }
  return out;
}

// The surge front (the largest x of a fluid particle plus half a spacing) must be within 20% of every
// published point up to T = t sqrt(2g/a) = 3, of Koshizuka & Oka and of Martin & Moyce's n^2 = 2 column
// (table [A]: Z = x / a against T = n t sqrt(g / a), the same T), both released by hand: solvers of every
// kind lead these experiments by roughly 10-20% around T = 1-1.5 (shared/validation/README.md), and with
// water's viscosity instead of the former artificial viscosity written as 6.26 Pa s this one does too (15%
// at this spacing, docs/physics.md, "The 2D dam break at full resolution"). A check of the set-up at CI
// resolution, not a validation (that is docs/physics.md, "Validation against experiments").
TEST_P(DamBreakFront, KoshizukaOkaAndMartinMoyceWithinTwentyPercent) {
  const double s = 0.1, g = 9.81, a = 1.0;
  std::string source;
  auto j = read_scene_json("dam-break-2d", source);
  j["spacing"] = s;
  j["solver"]["support"] = 2 * s;
  j["boundary"]["model"] = GetParam();
  j["neighbors"]["method"] = "all-pairs";
  const auto scene = load_scene<2, double>(j, source);

  // The published data, copied into the repository (data/validation/, with its source in the header).
  std::ifstream in(std::string(CELLSPH_SOURCE_DIR) + "/data/validation/koshizuka_oka_1996_front.tsv");
  ASSERT_TRUE(in) << "koshizuka_oka_1996_front.tsv not found";
  struct Point {
    double t, x;
    int source;  // 0: Koshizuka & Oka, 1: Martin & Moyce
  };
  std::vector<Point> ref;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double t = 0, x = 0;
    ls >> t >> x;
    if (t * std::sqrt(2 * g / a) <= 3) ref.push_back({t, x, 0});
  }
  ASSERT_GE(ref.size(), 10u);
  const auto mm = martin_moyce("[A]", 1);
  ASSERT_GE(mm.size(), 10u) << "martin_moyce_1952.txt: table [A] not found";
  for (const auto& [T, Z] : mm)
    if (T <= 3) ref.push_back({T / std::sqrt(2 * g / a), Z * a, 1});
  std::sort(ref.begin(), ref.end(), [](const Point& p, const Point& q) { return p.t < q.t; });

  ScopedThreads one(1);
  Simulation<2, double> sim(scene.solver, scene.particles);
  double worst[2] = {0, 0};
  int count[2] = {0, 0};
  for (const auto& [t, x, src] : ref) {
    sim.run_until(t);
    double front = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      if (sim.particles().kind[i] == 0) front = std::max(front, sim.particles().x[i][0]);
    front += s / 2;
    worst[src] = std::max(worst[src], std::abs(front - x) / x);
    ++count[src];
    EXPECT_NEAR(front, x, 0.2 * x) << (src ? "Martin & Moyce" : "Koshizuka & Oka") << ", t = " << sim.time()
                                   << " s";
  }
  std::cout << "[dam break] walls " << GetParam() << ": worst front error " << 100 * worst[0]
            << "% over Koshizuka & Oka's " << count[0] << " points, " << 100 * worst[1]
            << "% over Martin & Moyce's " << count[1] << "\n";
}

// The level (depth on the vertical) at x = 2 spacings from the back wall, one support length, so that
// the wall does not cut the kernel sum; and the particles clinging to the back wall by issue 14's
// criterion: within 2 spacings of it and more than 5 spacings above the level 4 spacings out (as
// scripts/wall_cling.py counts them). The far wall is not checked: its run-up jet is such a trail.
// Returns the worst |H - H_ref| and the number of clinging particles summed over the table's times.
std::pair<double, int> residual_height(const std::string& walls, const std::string& table, double s,
                                       double height, double tank_length, double tau_max) {
  const double g = 9.81, a = 1.0;  // the column is a = 1 m wide
  std::string source;
  auto j = read_scene_json("dam-break-2d", source);
  j["spacing"] = s;
  j["solver"]["support"] = 2 * s;
  j["boundary"]["model"] = walls;
  j["neighbors"]["method"] = "all-pairs";
  j["fluids"][0]["max"] = {a, height};
  j["boundary"]["walls"]["max"][0] = tank_length;
  j["domain"]["max"][0] = tank_length + 0.5;
  const auto scene = load_scene<2, double>(j, source);
  const auto ref = martin_moyce(table);
  EXPECT_GE(ref.size(), 8u) << "martin_moyce_1952.txt: table " << table << " not found";
  const std::vector<Probe> probes{{"wall", ProbeKind::Level, {2 * s, 0, 0}},
                                  {"out", ProbeKind::Level, {4 * s, 0, 0}}};
  const ProbeSampler<2, double> sampler(probes, scene.solver.density_kernel, double(scene.solver.support), s);

  ScopedThreads one(1);
  Simulation<2, double> sim(scene.solver, scene.particles);
  double worst = 0;
  int points = 0, cling = 0;
  for (const auto& [tau, h_ref] : ref) {
    if (tau <= 0 || tau > tau_max) continue;  // the initial column; the window
    sim.run_until(tau / std::sqrt(g / a));
    const auto level = sampler.sample(sim.particles());
    const double h = level[0] / height;  // H = h / (n^2 a), the column's height
    worst = std::max(worst, std::abs(h - h_ref));
    ++points;
    std::cout << "[dam break] " << walls << " " << table << " tau = " << tau << ": H = " << h << " against "
              << h_ref << "\n";
    const auto& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == 0 && p.x[i][0] < 2 * s && p.x[i][1] > level[1] + 5 * s) ++cling;
  }
  std::cout << "[dam break] Martin & Moyce " << table << ", walls " << walls << ", spacing " << s
            << ": worst residual height error " << worst << " (of the column height) over " << points
            << " points, " << cling << " clinging\n";
  return {worst, cling};
}

// Adami walls (every dam-break scene's): [A], the scene's column (1 m x 2 m) and tank (4 m) at the front
// test's 0.1 m, tau <= 2.5 (t <= 0.8 s, before the surge reflected at x = 4 m could come back); [B], a
// 1 m square column at 0.05 m (400 particles) in an 8 m tank, so that no reflection returns within the
// table's tau <= 6.3 (t = 2 s). Within 0.05 of the column height (issue 14's target) and no particle
// clinging to the back wall at any of the tables' times. Measured: worst 0.047 [A] and 0.045 [B];
// finer runs in docs/physics.md ("Validation against experiments").
TEST(DamBreakResidual, AdamiWallsMatchMartinMoyceWithoutClinging) {
  const auto [a_worst, a_cling] = residual_height("adami", "[A]", 0.1, 2.0, 4.0, 2.5);
  EXPECT_LE(a_worst, 0.05);
  EXPECT_EQ(a_cling, 0);
  const auto [b_worst, b_cling] = residual_height("adami", "[B]", 0.05, 1.0, 8.0, 7.0);
  EXPECT_LE(b_worst, 0.05);
  EXPECT_EQ(b_cling, 0);
}

// Akinci's walls hold the column at the back wall: 0.104 above table [A] at tau = 2 (0.234 with free
// slip, so not the no-slip friction). A known open problem of that wall model (docs/physics.md),
// asserted so that the check is seen to fail a sticky wall and a fix shows up here.
TEST(DamBreakResidual, AkinciWallsHoldTheColumnKnownProblem) {
  const auto [worst, cling] = residual_height("akinci", "[A]", 0.1, 2.0, 4.0, 2.5);
  EXPECT_GT(worst, 0.08);
  (void)cling;
}

INSTANTIATE_TEST_SUITE_P(Walls, DamBreakFront, ::testing::Values("akinci", "adami"),
                         [](const auto& p) { return p.param; });

}  // namespace
}  // namespace cellsph
