#pragma once
// What the tests that run every built-in scene share: the scenes' names, GoogleTest's name for a scene
// parameter (dashes to underscores: `Builtin/SceneStart.X/dam_break_2d`), and a scene at another spacing.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

// Scene j at f times its spacing: the support, the box's collision radius and any explicit particle mass
// scale with it (mass as f^dim), so the scene keeps its rest density, support / spacing ratio and every
// physical parameter; only the particle count changes. A support of more than kSupportAsLength spacings is
// a length of the scene's model, not a multiple of its spacing, and is kept: the paper's dam breaks take
// Table 1's h = 0.05 m (4.7 of their spacings); doubled with the spacing, one kernel spans their tank's
// whole depth (0.085 m) and the block collapses into one layer (docs/scenes.md, "Built-in scenes at
// another spacing").
constexpr double kSupportAsLength = 4;
inline nlohmann::json scaled_scene(nlohmann::json j, double f) {
  const int dim = j.value("dimension", 2);
  const double s = j["spacing"].get<double>();
  j["spacing"] = s * f;
  auto& solver = j["solver"];
  const double h = solver.value("support", 2 * s);
  solver["support"] = h > kSupportAsLength * s ? h : h * f;
  for (auto& ph : j["phases"])
    if (ph.contains("mass")) ph["mass"] = ph["mass"].get<double>() * std::pow(f, dim);
  if (j.contains("boundary") && j["boundary"].contains("box") && j["boundary"]["box"].contains("radius"))
    j["boundary"]["box"]["radius"] = j["boundary"]["box"]["radius"].get<double>() * f;
  return j;
}

}  // namespace cellsph::test
