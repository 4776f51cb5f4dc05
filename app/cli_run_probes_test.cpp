// `cellsph run` with probes: probes.csv against the resting tank's known depth and hydrostatic
// pressure, the same file after a resume as without one, and bad probe keys as input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cli_test_util.hpp"

namespace {

using cellsph::test::csv_rows;
using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
namespace fs = std::filesystem;

// The built-in hydrostatic tank (water 0.5 m deep in a 1 m tank, spacing 0.02 m), started in
// equilibrium, with a pressure probe 0.1 m above the floor, a level gauge and a velocity probe.
const std::string kProbes =
    " --set /initial_pressure=hydrostatic --set /probes_every=0.01"
    " --set '/probes=[{\"name\":\"p_0.1\",\"kind\":\"pressure\",\"at\":[0.5,0.1]},"
    "{\"name\":\"gauge\",\"kind\":\"level\",\"at\":[0.5,0]},"
    "{\"name\":\"u\",\"kind\":\"velocity\",\"at\":[0.3,0.25]}]'";

TEST(CliRunProbes, ARestingTankReadsItsDepthAndHydrostaticPressure) {
  TempDir dir;
  const auto r = run_cli(
      dir, "run hydrostatic-tank --until 0.2 --format csv --out " + q(dir / "out") + " --quiet" + kProbes);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rows = csv_rows(read_file(dir / "out" / "probes.csv"));
  ASSERT_GE(rows.size(), 2U);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"time", "p_0.1", "gauge", "u_x", "u_y"}));
  // One row per 0.01 s from t = 0 (at most one per step): 21 rows up to t = 0.2.
  EXPECT_EQ(rows.size() - 1, 21U);
  const double rho = 1000, g = 9.81, depth = 0.5, expected = rho * g * (depth - 0.1);
  EXPECT_EQ(rows[1][1], "0") << "at t = 0 the particles hold no pressure yet (the first step computes it)";
  double sum = 0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), 5U);
    const double t = std::stod(rows[k][0]);
    EXPECT_NEAR(t, 0.01 * double(k - 1), 0.002) << "sampled when the clock passes k * 0.01 s";
    // The level within half a spacing of the depth, the water at rest within 5 cm/s.
    EXPECT_NEAR(std::stod(rows[k][2]), depth, 0.01) << "t " << t;
    EXPECT_LT(std::hypot(std::stod(rows[k][3]), std::stod(rows[k][4])), 0.05) << "t " << t;
    if (k == 1) continue;
    // Weakly compressible SPH without density diffusion: the pressure rings by up to ~10% about rho g
    // (H - y) (measured: 3538-4176 Pa); its mean is hydrostatic within 2%.
    EXPECT_NEAR(std::stod(rows[k][1]), expected, 0.15 * expected) << "t " << t;
    sum += std::stod(rows[k][1]);
  }
  EXPECT_NEAR(sum / double(rows.size() - 2), expected, 0.02 * expected);
}

TEST(CliRunProbes, AResumedRunWritesTheSameFileAsAnUninterruptedOne) {
  TempDir dir;
  const std::string common = " --format csv --fps 40 --quiet" + kProbes;
  ASSERT_EQ(run_cli(dir, "run hydrostatic-tank --until 0.15 --out " + q(dir / "a") + common).code, 0);
  // Part-way, then continued; the run's probes.csv also gets rows past its last checkpoint dropped.
  ASSERT_EQ(run_cli(dir, "run hydrostatic-tank --until 0.07 --out " + q(dir / "b") + common).code, 0);
  const auto r = run_cli(dir, "run --resume " + q(dir / "b") + " --until 0.15 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(dir / "a" / "probes.csv"), read_file(dir / "b" / "probes.csv"));
}

TEST(CliRunProbes, BadProbesAreInputErrorsNamingTheKey) {
  TempDir dir;
  const struct {
    const char* set;
    const char* message;
  } cases[] = {
      {"/probes=[{\"name\":\"a\",\"at\":[0.5,0.1]}]", "/probes/0/kind"},
      {"/probes=[{\"name\":\"a\",\"kind\":\"height\",\"at\":[0.5,0.1]}]", "/probes/0/kind"},
      {"/probes=[{\"kind\":\"level\",\"at\":[0.5,0]}]", "/probes/0/name"},
      {"/probes=[{\"name\":\"a,b\",\"kind\":\"level\",\"at\":[0.5,0]}]", "/probes/0/name"},
      {"/probes=[{\"name\":\"a\",\"kind\":\"level\",\"at\":[0.5,0]},{\"name\":\"a\",\"kind\":\"pressure\","
       "\"at\":[0.5,0]}]",
       "/probes/1/name"},
      {"/probes=[{\"name\":\"u\",\"kind\":\"velocity\",\"at\":[0.5,0]},{\"name\":\"u_x\",\"kind\":\"level\","
       "\"at\":[0.5,0]}]",
       "/probes/1/name"},
      {"/probes=[{\"name\":\"a\",\"kind\":\"level\",\"at\":[0.5]}]", "/probes/0/at"},
      {"/probes=[{\"name\":\"a\",\"kind\":\"level\",\"at\":[0.5,0],\"depth\":1}]", "depth"},
      {"/probes={}", "/probes"},
      {"/probes_every=0", "/probes_every"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.set);
    const auto r =
        run_cli(dir, "run hydrostatic-tank --steps 1 --out " + q(dir / "out") + " --set '" + c.set + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
}

}  // namespace
