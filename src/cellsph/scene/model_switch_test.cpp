// A scene switched to another model (`--set /solver/model=NAME`): either it loads, or one message names
// every setting the model refuses with the --set edits that fit, and with those edits it loads
// (solver_reader.cpp, check_model_fits). Checked for every built-in scene and every model.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/scene.hpp"

namespace cellsph {
namespace {

// Loads the scene in its own dimension (double precision); InputError as load_scene throws it.
void load(const nlohmann::json& j, const std::string& source) {
  if (j.value("dimension", 2) == 2)
    (void)load_scene<2, double>(j, source);
  else
    (void)load_scene<3, double>(j, source);
}

// The edits of a message's "Add: --set A --set B" tail.
std::vector<std::string> suggested_edits(const std::string& message) {
  std::vector<std::string> edits;
  const std::size_t add = message.find(". Add: ");
  if (add == std::string::npos) return edits;
  const std::string key = "--set ";
  for (std::size_t k = message.find(key, add); k != std::string::npos; k = message.find(key, k + 1)) {
    const std::size_t start = k + key.size();
    const std::size_t end = message.find(' ', start);
    edits.push_back(message.substr(start, end == std::string::npos ? std::string::npos : end - start));
  }
  return edits;
}

TEST(ModelSwitch, EveryBuiltinSceneFitsEveryModelWithTheOneMessagesEdits) {
  int refused = 0;
  for (const auto& b : builtin_scenes()) {
    for (const std::string model : {"paper", "wcsph", "dfsph", "iisph"}) {
      std::string source;
      nlohmann::json j = read_scene_json(std::string(b.name), source);
      apply_scene_edits(j, {"/solver/model=" + model}, source);
      std::vector<std::string> edits;
      try {
        load(j, source);
        continue;
      } catch (const InputError& e) {
        edits = suggested_edits(e.what());
        ASSERT_FALSE(edits.empty()) << b.name << " as " << model
                                    << ": a refusal without the edits that fit: " << e.what();
      }
      ++refused;
      apply_scene_edits(j, edits, source);
      try {
        load(j, source);
      } catch (const InputError& e) {
        ADD_FAILURE() << b.name << " as " << model
                      << " with the suggested edits is refused again: " << e.what();
      }
    }
  }
  EXPECT_GT(refused, 10);  // the switches that need edits are many (WCSPH scenes to DFSPH and back, ...)
}

TEST(ModelSwitch, TheMessageNamesEverySettingAtOnce) {
  std::string source;
  nlohmann::json j = read_scene_json("hydrostatic-tank", source);
  apply_scene_edits(j, {"/solver/model=dfsph"}, source);
  try {
    load(j, source);
    FAIL() << "hydrostatic-tank as DFSPH loaded";
  } catch (const InputError& e) {
    const std::string m = e.what();
    for (const char* edit : {"--set /solver/artificial_viscosity/alpha=0", "--set /solver/density=mass",
                             "--set /solver/density_diffusion=null"})
      EXPECT_NE(m.find(edit), std::string::npos) << edit << " missing from: " << m;
  }
}

}  // namespace
}  // namespace cellsph
