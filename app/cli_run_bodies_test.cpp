// `cellsph run` with floating bodies (the built-in scene floating-box): bodies.csv's header and one row
// per body and frame, the same file after a resume as without one, and the device backend refused with
// exit 2 before anything is written.
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

// The scene at twice its spacing (about 1,000 fluid particles), to keep the runs short.
const std::string kCoarse = " --set /spacing=0.02 --set /solver/support=0.04";

TEST(CliRunBodies, BodiesCsvHasOneRowPerBodyAndFrame) {
  TempDir dir;
  // Two bodies: the scene's crate and a ball; frames at 0, 0.05, 0.1 s.
  const auto r = run_cli(dir, "run floating-box --until 0.1 --fps 20 --format csv --quiet" + kCoarse +
                                  " --out " + q(dir / "out") +
                                  " --set '/bodies/1={\"sphere\":{\"center\":[0.75,0.25],\"radius\":0.08},"
                                  "\"density\":2000}'");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rows = csv_rows(read_file(dir / "out" / "bodies.csv"));
  ASSERT_EQ(rows.size(), 1U + 3U * 2U);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"time", "body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx",
                                               "vy", "vz", "wx", "wy", "wz"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"0", "0", "0.40000000000000002", "0.5", "0", "1", "0", "0",
                                               "0", "0", "0", "0", "0", "0", "0"}));
  EXPECT_EQ(rows[2][1], "1");
  EXPECT_EQ(rows[2][2], "0.75");
  for (std::size_t k = 1; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), 15U);
    // The crate falls (5 cm above the water at the scene's spacing, 3 cm at this one: the water's
    // support reaches it before 0.05 s, so it falls no faster than freely).
    if (rows[k][1] == "0" && std::stod(rows[k][0]) > 0 && std::stod(rows[k][0]) < 0.06) {
      EXPECT_LT(std::stod(rows[k][10]), 0);
      EXPECT_GE(std::stod(rows[k][10]), -9.81 * std::stod(rows[k][0]) - 1e-9);
    }
    const double qn = std::hypot(std::hypot(std::stod(rows[k][5]), std::stod(rows[k][6])),
                                 std::hypot(std::stod(rows[k][7]), std::stod(rows[k][8])));
    EXPECT_NEAR(qn, 1, 1e-12);
  }
}

TEST(CliRunBodies, AResumedRunWritesTheSameFileAsAnUninterruptedOne) {
  TempDir dir;
  const std::string common = " --format csv --fps 40 --quiet" + kCoarse;
  ASSERT_EQ(run_cli(dir, "run floating-box --until 0.15 --out " + q(dir / "a") + common).code, 0);
  ASSERT_EQ(run_cli(dir, "run floating-box --until 0.07 --out " + q(dir / "b") + common).code, 0);
  const auto r = run_cli(dir, "run --resume " + q(dir / "b") + " --until 0.15 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(dir / "a" / "bodies.csv"), read_file(dir / "b" / "bodies.csv"));
  EXPECT_EQ(read_file(dir / "a" / "frame_00006.csv"), read_file(dir / "b" / "frame_00006.csv"));
}

// The host-emulated device (the CUDA backend's code path on the CPU): the CPU's bodies.csv and frames.
TEST(CliRunBodies, TheHostDeviceWritesTheCpusFiles) {
  TempDir dir;
  const std::string common = " --until 0.05 --format csv --fps 40 --quiet" + kCoarse;
  for (const std::string backend : {"cpu", "host-device"}) {
    const auto r =
        run_cli(dir, "run floating-box --backend " + backend + " --out " + q(dir / backend) + common);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const std::string a = read_file(dir / "cpu" / "bodies.csv");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, read_file(dir / "host-device" / "bodies.csv"));
  EXPECT_EQ(read_file(dir / "cpu" / "frame_00002.csv"), read_file(dir / "host-device" / "frame_00002.csv"));
}

}  // namespace
