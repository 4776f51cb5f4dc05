// The built-in dam-break-2d scene (Koshizuka & Oka 1996: a 1 m x 2 m water column in a 4 m tank),
// coarsened to 0.1 m, against the published surge front. Its set-up is the scene file's: WCSPH, cubic
// kernels, c = 10 sqrt(2 g H), water's viscosity 0.001 Pa s and Monaghan's artificial viscosity alpha = 0.01
// (which scales with h by itself), no-slip walls, a hydrostatic start; both wall models.
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
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

class DamBreakFront : public ::testing::TestWithParam<std::string> {};

// The surge front (the largest x of a fluid particle plus half a spacing) must be within 20% of every
// published point up to T = t sqrt(2g/a) = 3: solvers of every kind lead this hand-released experiment by
// roughly 10-20% around T = 1-1.5 (shared/validation/README.md), and with water's viscosity instead of the
// former artificial viscosity written as 6.26 Pa s this one does too (15% at this spacing, docs/physics.md,
// "The 2D dam break at full resolution"). A check of the set-up at CI resolution, not a validation.
TEST_P(DamBreakFront, KoshizukaOkaWithinTwentyPercent) {
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
  std::vector<std::pair<double, double>> ref;  // t [s], x [m]
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double t = 0, x = 0;
    ls >> t >> x;
    if (t * std::sqrt(2 * g / a) <= 3) ref.emplace_back(t, x);
  }
  ASSERT_GE(ref.size(), 10u);

  ScopedThreads one(1);
  Simulation<2, double> sim(scene.solver, scene.particles);
  double worst = 0;
  for (const auto& [t, x] : ref) {
    sim.run_until(t);
    double front = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      if (sim.particles().kind[i] == 0) front = std::max(front, sim.particles().x[i][0]);
    front += s / 2;
    worst = std::max(worst, std::abs(front - x) / x);
    EXPECT_NEAR(front, x, 0.2 * x) << "t = " << sim.time() << " s";
  }
  std::cout << "[dam break] walls " << GetParam() << ": worst front error " << 100 * worst << "% over "
            << ref.size() << " points\n";
}

INSTANTIATE_TEST_SUITE_P(Walls, DamBreakFront, ::testing::Values("akinci", "adami"),
                         [](const auto& p) { return p.param; });

}  // namespace
}  // namespace cellsph
