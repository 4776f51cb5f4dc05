// Replays, in the normal test suite (g++, and under the ASan + UBSan build of scripts/test.sh), every
// input the fuzz harnesses once failed on (fuzz/regressions/NAME/: the exact bytes, one file each, named
// after the bug) and every seed of their corpora (fuzz/corpus/NAME/), through the same code as the
// harnesses (fuzz/NAME_input.hpp). An input passes when it is read or refused with an InputError; an
// escaping exception fails the test, a memory error or undefined behaviour stops the sanitizer build.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cellsph/core/test_paths.hpp"
#include "checkpoint_input.hpp"
#include "frames_index_input.hpp"
#include "mesh_input.hpp"
#include "points_csv_input.hpp"
#include "scene_input.hpp"

namespace cellsph::fuzz {
namespace {

struct Harness {
  const char* name;
  void (*input)(const std::uint8_t*, std::size_t);
};

const Harness kHarnesses[] = {{"scene", scene_input},
                              {"points_csv", points_csv_input},
                              {"checkpoint", checkpoint_input},
                              {"frames_index", frames_index_input},
                              {"mesh", mesh_input}};

class FuzzReplay : public ::testing::TestWithParam<Harness> {};

TEST_P(FuzzReplay, RegressionsAndSeedsAreReadOrRefused) {
  const Harness h = GetParam();
  const std::filesystem::path root = std::filesystem::path(cellsph::test::source_dir()) / "fuzz";
  std::size_t seeds = 0;
  for (const char* kind : {"corpus", "regressions"}) {
    const auto dir = root / kind / h.name;
    if (!std::filesystem::exists(dir)) continue;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      std::ifstream in(e.path(), std::ios::binary);
      std::ostringstream ss;
      ss << in.rdbuf();
      const std::string bytes = ss.str();
      EXPECT_NO_THROW(h.input(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size())) << e.path();
      seeds += std::string(kind) == "corpus";
    }
  }
  EXPECT_GT(seeds, 0u) << "no seed corpus in " << (root / "corpus" / h.name);
  if (std::string(h.name) == "frames_index") std::filesystem::remove_all(detail_frames_index::folder());
}

INSTANTIATE_TEST_SUITE_P(Harnesses, FuzzReplay, ::testing::ValuesIn(kHarnesses),
                         [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace cellsph::fuzz
