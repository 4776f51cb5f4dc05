// Moving obstacles (boundary.obstacles[k].motion, solver/boundary/wall_motion.hpp) on the built program:
// bad motions and motion tables stop the start with one line naming the scene file and the key (exit 2,
// nothing written); a run with a table-driven piston resumes bit for bit; the device backend refuses a
// moving wall.
// GCC 12 reports a false -Wrestrict on chains of std::string operator+ at -O3 (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"

#include <gtest/gtest.h>

#include <string>

#include "cli_test_util.hpp"

namespace {

using cellsph::test::count_lines;
using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
using cellsph::test::write_file;
namespace fs = std::filesystem;

// A 2D tank with water pushed by a block (the obstacle) whose motion is MOTION.
std::string piston_scene(const std::string& motion) {
  return R"({"name": "piston", "dimension": 2, "spacing": 0.05,
  "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.5}],
  "solver": {"model": "wcsph", "support": 0.1, "density_kernel": "cubic", "pressure_kernel": "cubic",
             "eos": {"kind": "tait", "stiffness": 20000, "gamma": 7, "clamp_negative": true}},
  "time": {"end": 0.1, "stepping": "courant", "dt_max": 0.002},
  "fluids": [{"min": [0.15, 0], "max": [1, 0.3]}],
  "boundary": {"model": "adami", "slip": "no-slip",
               "walls": {"min": [0, 0], "max": [1, 0.6], "layers": 2, "weight": "volume"},
               "obstacles": [{"min": [0, 0], "max": [0.1, 0.5], "motion": )" +
         motion + R"(}]},
  "output": {"fps": 50, "formats": ["csv"], "checkpoint_every": 1}})";
}

TEST(CliMotion, BadMotionsStopTheStartWithOneLine) {
  TempDir dir;
  write_file(dir / "down.csv", "time,x,y\n0,0,0\n0.05,0.01,0\n0.04,0.02,0\n");
  write_file(dir / "short.csv", "time,x,y\n0,0\n");
  const struct {
    const char* name;
    std::string motion;
    const char* mention;
  } cases[] = {
      {"decreasing_time", R"({"table": "down.csv"})",
       "/boundary/obstacles/0/motion/table: down.csv line 4: column 1 (time): \"0.04\" does not increase"},
      {"missing_column", R"({"table": "short.csv"})",
       "/boundary/obstacles/0/motion/table: short.csv line 2: has 2 values, the header names 3 columns"},
      {"missing_file", R"({"table": "nope.csv"})",
       "/boundary/obstacles/0/motion/table: nope.csv: no such file"},
      {"unknown_kind", R"({"spin": {"omega": 1}})",
       "/boundary/obstacles/0/motion: give one motion: \"translate\", \"rotate\", \"oscillate\" or \"table\" "
       "(got spin)"},
      {"negative_period", R"({"oscillate": {"direction": [1, 0], "amplitude": 0.01, "period": -1}})",
       "/boundary/obstacles/0/motion/oscillate/period: must be > 0 s"},
      {"end_before_start", R"({"translate": {"velocity": [1, 0], "start": 1, "end": 0.5}})",
       "/boundary/obstacles/0/motion/translate/end: must not be before start"},
      {"axis_in_2d", R"({"rotate": {"axis": [0, 0, 1], "center": [0, 0], "omega": 1}})",
       "/boundary/obstacles/0/motion/rotate/axis: in 2D the rotation is about the out-of-plane axis"},
      {"misspelt_key", R"({"translate": {"velocity": [1, 0], "stat": 1}})",
       "/boundary/obstacles/0/motion/translate/stat"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    write_file(dir / "scene.json", piston_scene(c.motion));
    const fs::path out = dir / (std::string("out_") + c.name);
    const auto r = run_cli(dir, "run " + q(dir / "scene.json") + " --out " + q(out) + " --quiet");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("scene.json"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// The table is read beside the scene file, not in the working folder; the run resumes bit for bit.
TEST(CliMotion, TablePistonRunsAndResumesBitForBit) {
  TempDir dir;
  fs::create_directories(dir / "s");
  write_file(dir / "s" / "push.csv", "# a piston\ntime,x,y\n0,0,0\n0.02,0,0\n0.1,0.02,0\n");
  write_file(dir / "s" / "scene.json", piston_scene(R"({"table": "push.csv"})"));
  auto r = run_cli(dir, "run " + q(dir / "s" / "scene.json") + " --out " + q(dir / "whole") + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir,
              "run " + q(dir / "s" / "scene.json") + " --out " + q(dir / "parts") + " --quiet --until 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run --resume " + q(dir / "parts") + " --until 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 5; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".csv";
    const std::string a = read_file(dir / "whole" / name), b = read_file(dir / "parts" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs after resume";
  }
}

TEST(CliMotion, HostDeviceFramesEqualTheCpus) {
  TempDir dir;
  write_file(dir / "scene.json", piston_scene(R"({"translate": {"velocity": [0.1, 0]}})"));
  for (const std::string backend : {"cpu", "host-device"}) {
    const auto r = run_cli(dir, "run " + q(dir / "scene.json") + " --out " + q(dir / backend) +
                                    " --quiet --format csv --until 0.1 --backend " + backend);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  for (int f = 0; f <= 5; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".csv";
    const std::string a = read_file(dir / "cpu" / name), b = read_file(dir / "host-device" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs between the backends";
  }
}

}  // namespace
