// `cellsph scenes`: the built-in scenes, one line each that fits a terminal (name, 2D/3D, model, particles,
// a short title); `cellsph scenes NAME`: one scene's full description and its JSON (a built-in name or a
// scene file), the text to copy into a file of one's own.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/config.hpp"
#include "commands.hpp"

namespace cellsph::app {
namespace {

constexpr std::size_t kLineWidth = 100;

struct SceneSummary {
  SceneHeader header;
  std::string model;
  std::size_t particles = 0;
};

// The scene as it loads: its model and particle count (a built-in scene loads in milliseconds).
SceneSummary summarize(const std::string& name) {
  std::string source;
  const nlohmann::json j = read_scene_json(name, source);
  SceneSummary s{read_scene_header(j, source), {}, 0};
  auto take = [&](const auto& scene) {
    s.model = std::string(model_name(scene.solver.model));
    s.particles = scene.particles.size();
  };
  if (s.header.dim == 2)
    s.header.single_precision ? take(load_scene<2, float>(j, source))
                              : take(load_scene<2, double>(j, source));
  else
    s.header.single_precision ? take(load_scene<3, float>(j, source))
                              : take(load_scene<3, double>(j, source));
  return s;
}

// The description's first clause (up to ": ", " (" or the end of a sentence), cut with "..." to `width`
// characters.
std::string short_title(const std::string& description, std::size_t width) {
  std::size_t end = std::min(description.find(": "), description.find(" ("));
  for (std::size_t k = description.find(". "); k < end; k = description.find(". ", k + 1))
    if (k < 3 || description.compare(k - 3, 3, " al") != 0) end = k;  // not "et al."
  std::string t = description.substr(0, end);
  if (t.size() > width) t = t.substr(0, width - 3) + "...";
  return t;
}

// `text` broken at spaces into lines of at most `width` characters (a longer word stands alone).
std::string wrap(const std::string& text, std::size_t width) {
  std::string out, line;
  std::size_t k = 0;
  while (k < text.size()) {
    const std::size_t e = std::min(text.find(' ', k), text.size());
    const std::string word = text.substr(k, e - k);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    k = e + 1;
  }
  return out + line;
}

// A built-in scene's file text as written, else the scene file's JSON.
std::string scene_text(const std::string& name, const nlohmann::json& j) {
  for (const auto& b : builtin_scenes())
    if (b.name == name) return std::string(b.json);
  return j.dump(2) + "\n";
}

int list_scenes() {
  for (const auto& b : builtin_scenes()) {
    const SceneSummary s = summarize(std::string(b.name));
    char head[96];
    std::snprintf(head, sizeof head, "%-20s %dD  %-6s %8zu particles  ", std::string(b.name).c_str(),
                  s.header.dim, s.model.c_str(), s.particles);
    const std::string line = head;
    std::printf(
        "%s%s\n", line.c_str(),
        short_title(s.header.description, kLineWidth - std::min(line.size(), kLineWidth - 8)).c_str());
  }
  std::printf("\n`%s scenes NAME` prints a scene's full description and JSON.\n", program_name().c_str());
  return 0;
}

int show_scene(const std::string& name) {
  const SceneSummary s = summarize(name);
  std::string source;
  const nlohmann::json j = read_scene_json(name, source);
  std::printf("%s: %dD, %s, %zu particles (%s)\n\n%s\n\n%s", s.header.name.c_str(), s.header.dim,
              s.model.c_str(), s.particles, source.c_str(), wrap(s.header.description, kLineWidth).c_str(),
              scene_text(name, j).c_str());
  return 0;
}

}  // namespace

void register_scenes(CLI::App& app, int& result) {
  auto* scenes = app.add_subcommand(
      "scenes", "List the built-in scenes (one line each), or show one scene's description and JSON");
  auto name = std::make_shared<std::string>();
  scenes->add_option("name", *name, "A built-in scene's name or a scene file: its description and JSON");
  scenes->callback([name, &result] { result = name->empty() ? list_scenes() : show_scene(*name); });
}

}  // namespace cellsph::app
