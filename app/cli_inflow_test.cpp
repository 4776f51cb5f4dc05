// Emitters and sinks (docs/scenes.md "Inflow and outflow") on the built program: bad emitters and sinks
// stop the start with one line naming the key and value (exit 2, nothing written), a run of
// channel-inflow writes frames of changing counts (CSV, VTU, PLY, pictures) in ascending id order and
// resumes bit for bit, and the host-emulated device writes the CPU's frames.
// GCC 12 reports a false -Wrestrict on chains of std::string operator+ at -O3 (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"

#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_util.hpp"

namespace {

using cellsph::test::count_lines;
using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
namespace fs = std::filesystem;

TEST(CliInflow, BadEmittersAndSinksStopTheStartWithOneLine) {
  TempDir dir;
  const struct {
    const char* name;
    std::string args;
    const char* mention;
  } cases[] = {
      {"zero_normal", "--set '/emitters/0/normal=[0,0]'", "/emitters/0/normal: [0,0] has zero length"},
      {"negative_size", "--set /emitters/0/size=-0.1", "/emitters/0/size: -0.1 must be > 0"},
      {"negative_velocity", "--set /emitters/0/velocity=-1", "/emitters/0/velocity: -1 must be >= 0"},
      {"end_before_start", "--set /emitters/0/start=2 --set /emitters/0/end=1",
       "/emitters/0/end: 1 is before start 2"},
      {"sink_inverted", "--set '/sinks/0/min=[0.9,0]'", "/sinks/0/max: [0.8,0.2] is below min [0.9,0]"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path out = dir / (std::string("out_") + c.name);
    const auto r = run_cli(dir, "run channel-inflow " + c.args + " --out " + q(out) + " --quiet");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// The ids of a frame's CSV rows (the last column), in file order.
std::vector<long> csv_ids(const std::string& text) {
  std::vector<long> ids;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) ids.push_back(std::stol(line.substr(line.rfind(',') + 1)));
  return ids;
}

TEST(CliInflow, ChannelFramesOfChangingCountsResumeBitForBit) {
  TempDir dir;
  const std::string common = " --quiet --fps 50 --format csv,vtu,ply --set /output/checkpoint_every=1";
  auto r = run_cli(dir, "run channel-inflow --until 0.1 --render --out " + q(dir / "whole") + common);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run channel-inflow --until 0.05 --out " + q(dir / "parts") + common);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run --resume " + q(dir / "parts") + " --until 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  std::set<std::size_t> counts;
  for (int f = 0; f <= 5; ++f) {
    const std::string stem = "frame_0000" + std::to_string(f);
    for (const char* ext : {".csv", ".vtu", ".ply"}) {
      const std::string a = read_file(dir / "whole" / (stem + ext)),
                        b = read_file(dir / "parts" / (stem + ext));
      ASSERT_FALSE(a.empty()) << stem << ext;
      EXPECT_TRUE(a == b) << stem << ext << " differs after resume";
    }
    EXPECT_TRUE(fs::exists(dir / "whole" / "png" / (stem + ".png"))) << stem;
    const auto ids = csv_ids(read_file(dir / "whole" / (stem + ".csv")));
    for (std::size_t k = 1; k < ids.size(); ++k) ASSERT_LT(ids[k - 1], ids[k]) << stem << " row " << k;
    counts.insert(ids.size());
  }
  // Particles enter and leave: the frames do not all hold the same count.
  EXPECT_GT(counts.size(), 1u);
}

// The device backend (host-emulated: the CUDA backend's code path on the CPU) emits and removes between
// its steps: the CPU's frames byte for byte, counts and ids included.
TEST(CliInflow, HostDeviceFramesEqualTheCpus) {
  TempDir dir;
  for (const std::string backend : {"cpu", "host-device"}) {
    const auto r = run_cli(dir, "run channel-inflow --until 0.03 --fps 100 --format csv --quiet --backend " +
                                    backend + " --out " + q(dir / backend));
    ASSERT_EQ(r.code, 0) << r.err;
  }
  std::set<std::size_t> counts;
  for (int f = 0; f <= 3; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".csv";
    const std::string a = read_file(dir / "cpu" / name), b = read_file(dir / "host-device" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs between the backends";
    counts.insert(csv_ids(a).size());
  }
  EXPECT_GT(counts.size(), 1u);
}

}  // namespace
