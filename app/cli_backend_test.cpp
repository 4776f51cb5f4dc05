// `--backend` on the built program: cuda where it cannot run (this machine and CI have no GPU) is one
// line and exit 2 with nothing written; the host-emulated device ("host-device", the CUDA backend's
// code path on the CPU, for tests) gives the CPU's frames byte for byte, and a run resumes across
// backends.
// GCC 12 reports a false -Wrestrict on chains of std::string operator+ at -O3 (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cellsph/solver/backend.hpp"
#include "cli_test_util.hpp"

namespace {

using cellsph::test::kTiny;
using cellsph::test::q;
using cellsph::test::read_file;
using cellsph::test::run_cli;
using cellsph::test::TempDir;
using cellsph::test::write_file;
namespace fs = std::filesystem;

// The line a machine without a usable CUDA device prints for `where` (--backend or solver.backend).
void expect_no_cuda_line(const cellsph::test::RunResult& r, const std::string& where) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("cellsph: error: " + where + ": ", 0), 0u) << r.err;
  const std::string why = cellsph::cuda_built() ? "no usable CUDA device: none: cudaGetDeviceCount: "
                                                : "this build has no CUDA backend (configure with "
                                                  "-DCELLSPH_CUDA=ON and nvcc)";
  EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("use --backend cpu"), std::string::npos) << r.err;
}

TEST(CliBackend, CudaWithoutADeviceExitsWithCode2AndWritesNothing) {
  if (cellsph::cuda_device_report().ok) GTEST_SKIP() << "a CUDA device is present";
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "out") + " --backend cuda");
  expect_no_cuda_line(r, "--backend");
  EXPECT_FALSE(fs::exists(dir / "out"));
  // The scene key.
  std::string scene = kTiny;
  scene.replace(scene.find("\"solver\": {"), 11, "\"solver\": {\"backend\": \"cuda\", ");
  write_file(dir / "cuda.json", scene);
  r = run_cli(dir, "run " + q(dir / "cuda.json") + " --out " + q(dir / "out2"));
  expect_no_cuda_line(r, (dir / "cuda.json").string() + ": /solver/backend");
  EXPECT_FALSE(fs::exists(dir / "out2"));
  // The benchmark.
  r = run_cli(dir, "bench sph --quick --backend cuda");
  expect_no_cuda_line(r, "--backend");
}

TEST(CliBackend, UnknownBackendNamesTheOption) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  const auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "out") + " --backend tpu");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--backend: unknown backend 'tpu' (expected cpu or cuda)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(CliBackend, HostDeviceFramesEqualTheCpuAndResumeAcrossBackends) {
  TempDir dir;
  write_file(dir / "tiny.json", kTiny);
  auto r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "cpu") + " --quiet --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "dev") +
                       " --quiet --format csv --backend host-device");
  ASSERT_EQ(r.code, 0) << r.err;
  // Half on the device, then resumed on the CPU.
  r = run_cli(dir, "run " + q(dir / "tiny.json") + " --out " + q(dir / "mixed") +
                       " --quiet --format csv --backend host-device --until 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli(dir, "run --resume " + q(dir / "mixed") + " --until 0.1 --quiet --backend cpu");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 5; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".csv";
    const std::string a = read_file(dir / "cpu" / name);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == read_file(dir / "dev" / name)) << name << ": host-device differs from the cpu";
    EXPECT_TRUE(a == read_file(dir / "mixed" / name)) << name << ": resumed on the cpu differs";
  }
}

}  // namespace
