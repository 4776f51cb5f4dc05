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
#include "cellsph/core/test_paths.hpp"
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
  std::ifstream in(std::string(cellsph::test::source_dir()) + "/data/validation/martin_moyce_1952.txt");
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

// The published surge fronts up to T = t sqrt(2g/a) = 3, of Koshizuka & Oka and of Martin & Moyce's n^2 = 2
// column (table [A]: Z = x / a against T = n t sqrt(g / a), the same T), in time order.
struct FrontPoint {
  double t, x;
  int source;  // 0: Koshizuka & Oka, 1: Martin & Moyce
};
std::vector<FrontPoint> published_fronts() {
  const double g = 9.81, a = 1.0;
  // The published data, copied into the repository (data/validation/, with its source in the header).
  std::ifstream in(std::string(cellsph::test::source_dir()) +
                   "/data/validation/koshizuka_oka_1996_front.tsv");
  std::vector<FrontPoint> ref;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double t = 0, x = 0;
    ls >> t >> x;
    if (t * std::sqrt(2 * g / a) <= 3) ref.push_back({t, x, 0});
  }
  for (const auto& [T, Z] : martin_moyce("[A]", 1))
    if (T <= 3) ref.push_back({T / std::sqrt(2 * g / a), Z * a, 1});
  std::sort(ref.begin(), ref.end(), [](const FrontPoint& p, const FrontPoint& q) { return p.t < q.t; });
  return ref;
}

// A built-in 2D dam break at spacing s (support 2 s) with the given wall model, searched by all-pairs.
nlohmann::json coarsened(const std::string& scene_name, const std::string& walls, double s,
                         std::string& source) {
  auto j = read_scene_json(scene_name, source);
  j["spacing"] = s;
  j["solver"]["support"] = 2 * s;
  j["boundary"]["model"] = walls;
  j["neighbors"]["method"] = "all-pairs";
  return j;
}

// The surge front (the largest x of a fluid particle plus half a spacing) of a built-in 2D dam break
// coarsened to spacing s, at the times of `ref`; one thread.
std::vector<double> simulated_fronts(const std::string& scene_name, const std::string& walls, double s,
                                     const std::vector<FrontPoint>& ref) {
  std::string source;
  const auto scene = load_scene<2, double>(coarsened(scene_name, walls, s, source), source);
  ScopedThreads one(1);
  Simulation<2, double> sim(scene.solver, scene.particles);
  std::vector<double> out;
  for (const auto& r : ref) {
    sim.run_until(r.t);
    double front = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      if (sim.particles().kind[i] == 0) front = std::max(front, sim.particles().x[i][0]);
    out.push_back(front + s / 2);
  }
  return out;
}

// The surge front must be within 20% of every published point up to T = 3. Both experiments released
// the water by hand: solvers of every kind lead them by roughly 10-20% around T = 1-1.5
// (shared/validation/README.md), and with water's viscosity instead of the former artificial viscosity
// written as 6.26 Pa s this one does too (15% at this spacing, docs/physics.md, "The 2D dam break at full
// resolution"). A check of the set-up at CI resolution, not a validation (that is docs/physics.md,
// "Validation against experiments").
TEST_P(DamBreakFront, KoshizukaOkaAndMartinMoyceWithinTwentyPercent) {
  const auto ref = published_fronts();
  ASSERT_GE(ref.size(), 20u) << "koshizuka_oka_1996_front.tsv or martin_moyce_1952.txt [A] not found";
  const auto front = simulated_fronts("dam-break-2d", GetParam(), 0.1, ref);
  double worst[2] = {0, 0};
  int count[2] = {0, 0};
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const auto& [t, x, src] = ref[k];
    worst[src] = std::max(worst[src], std::abs(front[k] - x) / x);
    ++count[src];
    EXPECT_NEAR(front[k], x, 0.2 * x)
        << (src ? "Martin & Moyce" : "Koshizuka & Oka") << ", t = " << t << " s";
  }
  std::cout << "[dam break] walls " << GetParam() << ": worst front error " << 100 * worst[0]
            << "% over Koshizuka & Oka's " << count[0] << " points, " << 100 * worst[1]
            << "% over Martin & Moyce's " << count[1] << "\n";
}

// Issue 12: DFSPH's surge front no worse than WCSPH's at the same resolution. dam-break-2d-dfsph (DFSPH,
// Akinci walls, its CFL steps) against dam-break-2d (WCSPH) with the same walls, both at 0.1 m: the RMS
// of the relative front error over both experiments' points up to T = 3 may not exceed WCSPH's.
TEST(DamBreakFrontDfsph, NoWorseThanWcsphAtTheSameResolution) {
  const auto ref = published_fronts();
  ASSERT_GE(ref.size(), 20u);
  auto rms = [&ref](const std::vector<double>& front) {
    double sum = 0;
    for (std::size_t k = 0; k < ref.size(); ++k) sum += std::pow((front[k] - ref[k].x) / ref[k].x, 2);
    return std::sqrt(sum / double(ref.size()));
  };
  const double wcsph = rms(simulated_fronts("dam-break-2d", "akinci", 0.1, ref));
  const double dfsph = rms(simulated_fronts("dam-break-2d-dfsph", "akinci", 0.1, ref));
  std::cout << "[dam break] RMS front error over " << ref.size() << " points: WCSPH " << 100 * wcsph
            << "%, DFSPH " << 100 * dfsph << "%\n";
  EXPECT_LE(dfsph, wcsph);
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
  auto j = coarsened("dam-break-2d", walls, s, source);
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
            << " points, " << cling << " clinging, " << sim.wall_corrections()
            << " put back out of the walls\n";
  return {worst, cling};
}

// Adami walls (every dam-break scene's): [A], the scene's column (1 m x 2 m) and tank (4 m) at the front
// test's 0.1 m, tau <= 2.5 (t <= 0.8 s, before the surge reflected at x = 4 m could come back); [B], a
// 1 m square column at 0.05 m (400 particles) in an 8 m tank, so that no reflection returns within the
// table's tau <= 6.3 (t = 2 s). Within 0.05 of the column height (issue 14's target) and no particle
// clinging to the back wall at any of the tables' times. Measured: worst 0.046 [A] and 0.045 [B];
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
