// `cellsph bench steps`: runs, reports the three runs, and the two per-particle runs (work sets and every
// density computed) do the same steps and force evaluations, as the solver test requires bit for bit.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "cli_test_util.hpp"

namespace cellsph::test {
namespace {

struct Row {
  unsigned long long steps = 0, force = 0, density = 0;
  bool found = false;
};

Row row(const std::string& out, const std::string& name) {
  std::istringstream in(out);
  std::string line;
  Row r;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string first;
    l >> first;
    if (first != name) continue;
    Row got;
    l >> got.steps >> got.force >> got.density;
    got.found = static_cast<bool>(l);
    if (got.found) r = got;  // the summary line also starts with 'courant'
  }
  return r;
}

TEST(BenchCli, StepsComparesPerParticleWithTheGlobalStep) {
  TempDir dir;
  // The 2D dam break with the paper model, 0.1 m spacing (200 particles), c = 3 m/s, Akinci walls (the
  // scene's Adami walls need global steps).
  const auto r = run_cli(
      dir,
      "bench steps --scene dam-break-2d --set '/solver/model=\"paper\"' --set '/boundary/model=\"akinci\"' "
      "--set /solver/artificial_viscosity/alpha=0 "
      "--set /spacing=0.1 "
      "--set /solver/support=0.2 --set /phases/0/viscosity=0.5 --set /solver/eos/stiffness=9000 "
      "--dt-max 0.01 --end 0.2 --sample 0.1 --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  const Row g = row(r.out, "courant"), pp = row(r.out, "per-particle"), all = row(r.out, "per-particle/all");
  ASSERT_TRUE(g.found && pp.found && all.found) << r.out;
  EXPECT_EQ(pp.steps, all.steps);
  EXPECT_EQ(pp.force, all.force);
  EXPECT_LE(pp.density, all.density);
  EXPECT_GT(g.force, 0u);
  EXPECT_NE(r.out.find("KE glob"), std::string::npos) << r.out;
}

TEST(BenchCli, StepsRejectsBadEdits) {
  TempDir dir;
  EXPECT_EQ(run_cli(dir, "bench steps --set nopointer").code, 2);
  // A bare word is a string; the scene reader rejects an unknown model, naming its path.
  const auto r = run_cli(dir, "bench steps --set /solver/model=papr");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/solver/model"), std::string::npos) << r.err;
  EXPECT_EQ(run_cli(dir, "bench steps --scene no-such-scene").code, 2);
  EXPECT_EQ(run_cli(dir, "bench steps --dt-max 0").code, 2);
}

}  // namespace
}  // namespace cellsph::test
