#pragma once
// libFuzzer harness: the scene reader as `cellsph run` uses it. The input is a scene file, optionally led
// by lines starting with '@' that are `--set` edits ("@/spacing=0.1" is `--set /spacing=0.1`). The scene is
// read from a file (JsonReader::parse_file, with its line:column messages), edited (apply_scene_edits),
// its header read (read_scene_header) and loaded in the dimension and precision it names (load_scene,
// which makes the particles). Bad input must end in InputError; anything else (another exception, a
// crash, a sanitizer report, a leak, a hang) is a finding. The particles a scene may make are capped by a
// small memory budget (SceneLimits), as on a machine with a few MiB, so that an input cannot ask for hours.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/scene/scene.hpp"
#include "fuzz_util.hpp"

namespace cellsph::fuzz {

namespace detail_scene {

template <int Dim, class Real>
void load(const nlohmann::json& j, const std::string& source) {
  SceneLimits limits;
  limits.memory_bytes = 4 << 20;  // about 6000 particles at 664 bytes each
  const Scene<Dim, Real> s = load_scene<Dim, Real>(j, source, limits);
  // The reader's promise: a loaded scene's particles and settings are what the solver may start from.
  (void)s;
}

}  // namespace detail_scene

// One input of the harness (fuzz/scene_fuzz.cpp); also replayed by fuzz/regressions_test.cpp.
inline void scene_input(const std::uint8_t* data, std::size_t size) {
  using namespace detail_scene;
  static MemFile file("scene.json");
  std::string_view in(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> edits;
  while (!in.empty() && in.front() == '@') {
    const auto nl = in.find('\n');
    edits.emplace_back(in.substr(1, nl == std::string_view::npos ? in.npos : nl - 1));
    in = nl == std::string_view::npos ? std::string_view{} : in.substr(nl + 1);
  }
  file.set(in);
  try {
    std::string source;
    nlohmann::json j = read_scene_json(file.path().string(), source);
    apply_scene_edits(j, edits, source);
    const SceneHeader h = read_scene_header(j, source);
    if (h.dim == 2 && !h.single_precision) load<2, double>(j, source);
    if (h.dim == 2 && h.single_precision) load<2, float>(j, source);
    if (h.dim == 3 && !h.single_precision) load<3, double>(j, source);
    if (h.dim == 3 && h.single_precision) load<3, float>(j, source);
  } catch (const InputError&) {
    // bad input, reported as such
  }
}

}  // namespace cellsph::fuzz
