#pragma once
// What the tests that run every built-in scene share: the scenes' names, and GoogleTest's name for a scene
// parameter (dashes to underscores: `Builtin/SceneStart.X/dam_break_2d`).
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cellsph/scene/builtin_scenes.hpp"

namespace cellsph::test {

inline std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> v;
  for (const auto& s : builtin_scenes()) v.emplace_back(s.name);
  return v;
}

inline std::string scene_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  std::replace(n.begin(), n.end(), '-', '_');
  return n;
}

}  // namespace cellsph::test
