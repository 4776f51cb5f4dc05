// `cellsph run` and `cellsph scenes` on the built program: outputs and their index, resume bit for
// bit, error exits (2 for bad input, 3 for an unstable run), help and listing.
// GCC 12 reports a false -Wrestrict on chains of std::string operator+ at -O3 (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cellsph/render/image.hpp"
#include "cli_test_util.hpp"

namespace {

using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
using cellsph::test::write_file;
namespace fs = std::filesystem;

using cellsph::test::kTiny;

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == '\n') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == sep)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

TEST(CliRun, WritesEveryFormatTheIndexAndTheCollection) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "out") + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto idx = lines(read_file(dir / "out" / "frames.csv"));
  ASSERT_FALSE(idx.empty());
  EXPECT_EQ(idx[0], "frame,time,vtu,ply,csv");
  ASSERT_EQ(idx.size(), 1u + 6u) << "frames at t = 0, 0.02, ..., 0.1";
  double last_time = -1;
  for (std::size_t k = 1; k < idx.size(); ++k) {
    const auto cols = split(idx[k], ',');
    ASSERT_EQ(cols.size(), 5u) << idx[k];
    EXPECT_EQ(std::stoul(cols[0]), k - 1);
    const double t = std::stod(cols[1]);
    EXPECT_GT(t, last_time);
    EXPECT_NEAR(t, 0.02 * double(k - 1), 0.0021) << "frame times follow --fps within one step";
    last_time = t;
    for (std::size_t c = 2; c < 5; ++c) EXPECT_TRUE(fs::exists(dir / "out" / cols[c])) << cols[c];
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "particles.pvd"));
  EXPECT_TRUE(fs::exists(dir / "out" / "checkpoint.bin"));
  const auto csv = lines(read_file(dir / "out" / "frame_00005.csv"));
  ASSERT_EQ(csv.size(), 1u + 72u);
  EXPECT_EQ(csv[0].rfind("x,y,vx,vy,density,pressure,phase", 0), 0u) << csv[0];
  for (const auto& e : fs::directory_iterator(dir / "out"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "left behind: " << e.path();
}

TEST(CliRun, ResumeContinuesBitForBit) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  auto r =
      run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "whole") + " --quiet --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  // Stop half-way, then resume to the same end.
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "parts") +
                       " --quiet --format csv --until 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_FALSE(fs::exists(dir / "parts" / "frame_00005.csv"));
  r = run_cli(dir, "run --resume " + q(dir / "parts") + " --until 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 5; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".csv";
    const std::string a = read_file(dir / "whole" / name), b = read_file(dir / "parts" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs after resume";
  }
  EXPECT_EQ(read_file(dir / "whole" / "frames.csv"), read_file(dir / "parts" / "frames.csv"));
}

TEST(CliRun, ResumeExtendsAFinishedRunAndRestartsWithoutCheckpoint) {
  TempDir dir;
  std::string scene = kTiny;
  scene.replace(scene.find("\"checkpoint_every\": 1"), 21, "\"checkpoint_every\": 100");
  write_file(dir / "tiny.json", scene);
  auto r =
      run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "whole") + " --quiet --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  // No frame reaches a checkpoint here; the end state is saved, so the run can be extended.
  r = run_cli(
      dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "ext") + " --quiet --format csv --until 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run --resume " + q(dir / "ext") + " --until 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_file(dir / "whole" / "frame_00005.csv") == read_file(dir / "ext" / "frame_00005.csv"));
  // A run killed before any checkpoint starts again from t = 0 (same result, deterministic).
  fs::remove(dir / "ext" / "checkpoint.bin");
  r = run_cli(dir, "run --resume " + q(dir / "ext") + " --until 0.1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("starting again from t = 0"), std::string::npos) << r.err;
  EXPECT_TRUE(read_file(dir / "whole" / "frame_00005.csv") == read_file(dir / "ext" / "frame_00005.csv"));
  EXPECT_EQ(read_file(dir / "whole" / "frames.csv"), read_file(dir / "ext" / "frames.csv"));
}

TEST(CliRun, ResumeFromADamagedOrOldCheckpointExitsWithCode2NamingTheFile) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  auto r = run_cli(
      dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "o") + " --quiet --format csv --until 0.04");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto ckpt = dir / "o" / "checkpoint.bin";
  std::string bytes = read_file(ckpt);
  ASSERT_EQ(bytes.substr(0, 8), "CSPHCKPT");
  const std::size_t at = bytes.size() - 9;  // the last particle's kind, just before the checksum
  bytes[at] = static_cast<char>(bytes[at] ^ 1);
  write_file(ckpt, bytes);
  r = run_cli(dir, "run --resume " + q(dir / "o") + " --until 0.1 --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(ckpt.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("checksum mismatch"), std::string::npos) << r.err;
  // The format of earlier builds (magic CSPHRUN1) is named as such.
  write_file(ckpt, std::string("CSPHRUN1") + std::string(64, '\0'));
  r = run_cli(dir, "run --resume " + q(dir / "o") + " --until 0.1 --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("earlier cellsph"), std::string::npos) << r.err;
}

TEST(CliRun, SameResultWithEveryNeighbourMethod) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  std::string reference;
  for (const char* m : {"all-pairs", "spatial-hash", "cell-index", "sorted-grid", "kd-tree"}) {
    const auto out = dir / m;
    const auto r = run_cli(
        dir, "run " + q(dir / "tiny.json") + " --out " + q(out) + " --quiet --format csv --method " + m);
    ASSERT_EQ(r.code, 0) << m << ": " << r.err;
    const std::string last = read_file(out / "frame_00005.csv");
    ASSERT_FALSE(last.empty());
    if (reference.empty())
      reference = last;
    else
      EXPECT_TRUE(last == reference) << m << " gives different physics from all-pairs";
  }
}

TEST(CliRun, BadSceneExitsWithCode2NamingFileAndKey) {
  TempDir dir;
  std::string bad = kTiny;
  bad.replace(bad.find("\"spacing\""), 9, "\"spacng\": 1, \"spacing\"");
  write_file(dir / "bad.json", bad);
  const auto r = run_cli(dir, "run " + q(dir / "bad.json") + " --out " + q(dir / "out"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/spacng"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "frames.csv"));

  const auto r2 = run_cli(dir, "run no-such-scene");
  EXPECT_EQ(r2.code, 2);
  EXPECT_NE(r2.err.find("no-such-scene"), std::string::npos) << r2.err;
  EXPECT_NE(r2.err.find("dam-break-2d"), std::string::npos) << "lists the built-in scenes: " << r2.err;

  const auto r3 = run_cli(dir, "run " + q(dir / "bad.json") + " --method octree");
  EXPECT_EQ(r3.code, 2);

  // An output folder that cannot be made (a file is in the way) is named, with the reason.
  write_file(dir / "afile", "x");
  write_file(dir / "tiny.json", kTiny);
  const auto r4 = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "afile" / "out"));
  EXPECT_EQ(r4.code, 2) << r4.err;
  EXPECT_NE(r4.err.find("output folder '" + (dir / "afile" / "out").string() + "': cannot be created"),
            std::string::npos)
      << r4.err;
}

TEST(CliRun, SetEditsTheSceneAndIsSavedForResume) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  // The tiny scene at half its spacing: 4x the fluid particles, a different run.
  auto r =
      run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "fine") +
                       " --quiet --format csv --until 0.04 --set /spacing=0.025 --set /solver/support=0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "coarse") +
                       " --quiet --format csv --until 0.04");
  ASSERT_EQ(r.code, 0) << r.err;
  auto fluid_rows = [](const std::string& csv) {
    std::size_t n = 0;
    const auto rows = lines(csv);
    const auto head = split(rows.at(0), ',');
    std::size_t kind = 0;
    while (kind < head.size() && head[kind] != "kind") ++kind;
    for (std::size_t k = 1; k < rows.size(); ++k) n += split(rows[k], ',').at(kind) == "0" ? 1 : 0;
    return n;
  };
  const auto coarse = fluid_rows(read_file(dir / "coarse" / "frame_00000.csv"));
  ASSERT_GT(coarse, 0u);
  EXPECT_EQ(fluid_rows(read_file(dir / "fine" / "frame_00000.csv")), 4 * coarse);
  // The edited scene is what run.json keeps, so a resume continues the edited run.
  EXPECT_NE(read_file(dir / "fine" / "run.json").find("0.025"), std::string::npos);
  r = run_cli(dir, "run --resume " + q(dir / "fine") + " --until 0.06 --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(fluid_rows(read_file(dir / "fine" / "frame_00003.csv")), 4 * coarse);
  r = run_cli(dir, "run --resume " + q(dir / "fine") + " --until 0.08 --set /spacing=0.05");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--set"), std::string::npos) << r.err;
  // Bad edits exit with code 2 before anything is written, naming the edit or the key path.
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "bad") + " --set spacing=1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("spacing=1"), std::string::npos) << r.err;
  r = run_cli(dir,
              "run " + q(dir / "tiny.json") + " --out " + q(dir / "bad") + " --set /solver/eos/kind=taitt");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/solver/eos/kind"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("taitt"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "bad" / "frames.csv"));
}

// A scene without /solver/eos/stiffness gets c = 10 sqrt(2 g H) (scene/sound_speed_default.cpp): the
// start says the value and how it was found, and run.json keeps it. The tiny scene's own stiffness
// (Tait, k = 2e4 Pa: c = 11.8 m/s) compresses the bottom of its 0.6 m column by rho0 g H / (7 k) = 4.2%
// once the column weighs on it, over the 3% bound, and the run says so once, then in the summary.
TEST(CliRun, DerivedStiffnessIsSaidAndAWeakOneWarned) {
  TempDir dir;
  std::string s = kTiny;
  const std::string given = "\"stiffness\": 20000, ";
  s.erase(s.find(given), given.size());
  write_file(dir / "derived.json", s);
  auto r = run_cli(dir, "run " + q(dir / "derived.json") + " --out " + q(dir / "derived") + " --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("cellsph: /solver/eos/stiffness = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(not in the scene: speed of sound c = 10 sqrt(2 g H) = "), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const std::string run = read_file(dir / "derived" / "run.json");
  EXPECT_NE(run.find("\"key\": \"/solver/eos/stiffness\""), std::string::npos) << run;

  write_file(dir / "tiny.json", kTiny);
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "weak") + " --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string largest = "phase 0 (water): largest density ";
  const std::size_t first = r.err.find("cellsph: warning: t = ");
  ASSERT_NE(first, std::string::npos) << r.err;
  EXPECT_NE(r.err.find(largest, first), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("raise /solver/eos/stiffness (now 2e+04, speed of sound 11.8 m/s)"), std::string::npos)
      << r.err;
  const std::size_t summary = r.err.find("cellsph: done: ");
  ASSERT_NE(summary, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("         warning: t = ", summary), std::string::npos) << r.err;
  // Once each: the largest density is named twice, in its warning and in the summary.
  std::size_t count = 0;
  for (std::size_t at = r.err.find(largest); at != std::string::npos; at = r.err.find(largest, at + 1))
    ++count;
  EXPECT_EQ(count, 2U) << r.err;
}

TEST(CliRun, UnstableRunStopsWithDiagnosisAndCode3) {
  TempDir dir;
  std::string s = kTiny;
  // Gravity a million times too strong and no walls: particles leave the domain within a few steps.
  s.replace(s.find("\"eos\""), 5, "\"gravity\": [0, -1e7], \"eos\"");
  s.replace(s.find("\"boundary\""), 10, "\"domain\"");
  s.replace(s.find("{\"box\": "), 8, "");
  s.replace(s.find("}},\n  \"output\""), 2, "}");
  write_file(dir / "unstable.json", s);
  const auto r = run_cli(dir, "run " + q(dir / "unstable.json") + " --out " + q(dir / "out") + " --quiet");
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("step"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("particle"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "frame_00000.vtu")) << "frames written before the blow-up stay";
}

// A solve stopped at max_iterations above its bound gets a warning line naming the step, the solve, its
// sweeps, the error reached and the bound, for the first ten such solves of a run; the progress line and
// the summary count them all.
TEST(CliRun, SolvesStoppedAtMaxIterationsAreLogged) {
  TempDir dir;
  // One sweep each, bounds no sweep meets: both solves of every step stop at max_iterations.
  const auto r =
      run_cli(dir, "run dam-break-2d-dfsph --steps 8 --fps 1 --format csv --out " + q(dir / "out") +
                       " --set /solver/dfsph/min_iterations=1 --set /solver/dfsph/max_iterations=1"
                       " --set /solver/dfsph/max_density_error=1e-9"
                       " --set /solver/dfsph/max_divergence_error=1e-9"
                       " --set /time/dt_column=0");  // steps of dt_max, 5 ms: the times below
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> warnings;
  for (std::size_t at = r.err.find("cellsph: warning: "); at != std::string::npos;
       at = r.err.find("cellsph: warning: ", at + 1))
    warnings.push_back(r.err.substr(at, r.err.find('\n', at) - at));
  // Step 1 starts at rest, its divergence error 0: one solve; two in each later step. Ten in all by step 6.
  ASSERT_EQ(warnings.size(), 6u) << r.err;
  EXPECT_EQ(warnings[0].rfind("cellsph: warning: step 1 (t = 0.005 s): the DFSPH constant-density solve "
                              "stopped at max_iterations (1 sweep) with average error ",
                              0),
            0u)
      << warnings[0];
  EXPECT_NE(warnings[0].find("%, above its bound 1e-09%"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find("(and "), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[1].rfind("cellsph: warning: step 2 (t = 0.01 s): ", 0), 0u) << warnings[1];
  EXPECT_NE(warnings[1].find(", above its bound 1e-09% (and one more solve of this step)"), std::string::npos)
      << warnings[1];
  EXPECT_EQ(warnings[5].rfind("cellsph: warning: step 6 (t = 0.03 s): ", 0), 0u) << warnings[5];
  EXPECT_NE(
      warnings[5].find("; further ones are counted on the progress line and in the summary, not logged"),
      std::string::npos)
      << warnings[5];
  EXPECT_NE(r.err.find(", 15 solves stopped at max_iterations (last: step 8, error "), std::string::npos)
      << r.err;
}

TEST(CliRun, RenderWritesOnePngPerFrame) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "out") +
                                  " --quiet --format vtu --render --until 0.04 --color-by pressure");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 2; ++f)
    EXPECT_TRUE(fs::exists(dir / "out" / "png" / ("frame_0000" + std::to_string(f) + ".png"))) << f;
}

// Pictures show what the water hits (issue 52 item 7): dam-break-3d's box obstacle changes the first
// frame against the same scene without it, in grey, so neither the tank's near walls (cut away) nor
// the fluid hides it. Before, walls and obstacles were not drawn and the two frames were alike.
TEST(CliRun, RenderDrawsTheSolidsInGrey) {
  TempDir dir;
  auto frame = [&](const std::string& name, const std::string& extra) {
    const auto r = run_cli(
        dir, "run dam-break-3d --out " + q(dir / name) + " --quiet --format csv --render --steps 0" + extra);
    EXPECT_EQ(r.code, 0) << r.err;
    return cellsph::read_png(dir / name / "png" / "frame_00000.png");
  };
  const cellsph::Image with = frame("with", ""), without = frame("without", " --set /boundary/obstacles=[]");
  ASSERT_EQ(with.width, without.width);
  ASSERT_EQ(with.height, without.height);
  std::size_t changed = 0, grey = 0;
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const cellsph::Rgb8 a = with.at(x, y), b = without.at(x, y);
      const auto diff = [](int u, int v) { return u > v ? u - v : v - u; };
      if (diff(a[0], b[0]) + diff(a[1], b[1]) + diff(a[2], b[2]) < 24) continue;
      ++changed;
      const int hi = std::max({a[0], a[1], a[2]}), lo = std::min({a[0], a[1], a[2]});
      if (hi - lo <= 24) ++grey;
    }
  // The obstacle, 0.3 x 0.6 m of a 4 x 3 m tank seen at 1280 x 720: thousands of pixels.
  EXPECT_GT(changed, 2000U);
  EXPECT_GT(grey, changed * 9 / 10) << grey << " of " << changed;
}

TEST(CliRun, SurfaceWritesOneMeshPerFrameAndPhase) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "out") +
                                  " --quiet --format csv --surface --surface-format obj --until 0.04");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 2; ++f) {
    const auto mesh = read_file(dir / "out" / "surface" / ("surface_0_0000" + std::to_string(f) + ".obj"));
    EXPECT_NE(mesh.find("\nv "), std::string::npos) << "frame " << f << " has no vertices";
    EXPECT_NE(mesh.find("\nf "), std::string::npos) << "frame " << f << " has no faces";
  }
  const auto bad =
      run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "bad") + " --surface-format stl");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("stl"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad")) << "a bad option must not leave an output folder behind";
}

TEST(CliRun, HelpDocumentsEveryOption) {
  TempDir dir;
  const auto r = run_cli(dir, "run --help");
  EXPECT_EQ(r.code, 0);
  for (const char* opt :
       {"--out", "--threads", "--method", "--until", "--steps", "--fps", "--format", "--render", "--color-by",
        "--surface", "--surface-format", "--quiet", "--resume", "--set", "default"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt << " missing from --help:\n" << r.out;
}

}  // namespace
