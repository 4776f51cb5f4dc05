// `cellsph doctor` on the built program: exit 0 and one line for each thing it reports.
#include <gtest/gtest.h>

#include <string>

#include "cli_test_util.hpp"

namespace {

TEST(CliDoctor, ReportsBackendsThreadsCpuAndLibraries) {
  cellsph::test::TempDir dir;
  const auto r = cellsph::test::run_cli(dir, "doctor");
  ASSERT_EQ(r.code, 0) << r.err;
  // "build for any x86-64 CPU" or "build for this machine's CPU" (CELLSPH_NATIVE).
  for (const char* line :
       {"build for ", "backends:     cpu (OpenMP)", "device:", "threads:", "cpu:          AVX2 ",
        "mpi:          ", "compiler:", "nlohmann-json 3.", "nanoflann 1.", "OpenVDB ", "libpng 1."})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " in:\n" << r.out;
}

}  // namespace
