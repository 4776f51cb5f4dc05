#pragma once
// Scenes: what a user edits. A scene file (JSON, documented key by key in docs/scenes.md) describes
// the fluid blocks, walls and obstacles, the phases, the solver, time stepping, neighbour search and
// output. load_scene() validates everything before anything runs and turns it into initial particles
// and a SolverConfig; every error names the file, the key path and the value (InputError, exit 2).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellsph/core/error.hpp"
#include "cellsph/probes/probes.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

// What must be known before the scene can be instantiated for a dimension and precision.
struct SceneHeader {
  std::string name;
  std::string description;
  int dim = 2;
  bool single_precision = false;  // "precision": "float"
};

// Output settings of a scene (command-line options override them).
struct OutputSettings {
  double end_time = 1.0;                    // [s]
  double fps = 30;                          // frames per simulated second
  std::vector<std::string> formats{"vtu"};  // any of vtu, ply, csv
  int checkpoint_every = 10;                // frames between checkpoints; 0 = none
  std::string color_by = "phase";           // phase | speed | pressure
  int up_axis = 1;                          // world axis shown upwards in pictures
};

// A setting the scene left out that load_scene derived from the scene itself rather than take a fixed
// default (docs/scenes.md, "Derived settings"): `cellsph run` prints it at the start and keeps it in
// run.json.
struct DerivedSetting {
  std::string key;  // JSON pointer of the setting, e.g. /solver/eos/stiffness
  double value = 0;
  std::string why;  // how it was derived, with the numbers
};

template <int Dim, class Real>
struct Scene {
  SceneHeader header;
  std::string source;  // file name or "built-in scene NAME", for messages
  Real spacing = 0;    // particle spacing [m]
  SolverConfig<Dim, Real> solver;
  Particles<Dim, Real> particles;  // initial fluid and boundary particles
  OutputSettings output;
  std::array<double, 3> view_lo{}, view_hi{};  // the box drawn in pictures
  std::vector<Probe> probes;                   // sampled into probes.csv (probes/probes.hpp)
  double probes_every = 0.01;                  // [s] between probe samples
  std::vector<DerivedSetting> derived;         // the settings derived from the scene
  std::vector<std::string> warnings;           // what the scene's geometry resolves poorly, one sentence each
};

// A scene's JSON text: `name_or_path` is a built-in scene name or a path to a .json file. `source`
// receives a label for error messages.
nlohmann::json read_scene_json(const std::string& name_or_path, std::string& source);

// Edits a scene's JSON before it is read, as `--set` does on the command line. Each edit is
// "/json/pointer=value": the value (JSON; anything that does not parse as JSON is taken as a string,
// so `/boundary/model=adami` works unquoted) replaces or adds the one at the pointer (RFC 6901,
// e.g. /phases/0/viscosity). A malformed edit throws InputError naming it. `source` gains " (edited: ...)"
// so later messages say that the scene is not the file's. Keys are not checked here: the strict
// reader of load_scene rejects a misspelt one, naming its path.
void apply_scene_edits(nlohmann::json& j, const std::vector<std::string>& edits, std::string& source);

SceneHeader read_scene_header(const nlohmann::json& j, const std::string& source);

// What load_scene may make. The particles a scene asks for are counted before any is made, at about
// 256 bytes a particle plus 8 per neighbour pair, against this memory.
struct SceneLimits {
  double memory_bytes = 0;  // 0: this machine's physical memory; the fuzz harness sets a few MiB
};

template <int Dim, class Real>
Scene<Dim, Real> load_scene(const nlohmann::json& j, const std::string& source,
                            const SceneLimits& limits = {});

extern template Scene<2, float> load_scene<2, float>(const nlohmann::json&, const std::string&,
                                                     const SceneLimits&);
extern template Scene<2, double> load_scene<2, double>(const nlohmann::json&, const std::string&,
                                                       const SceneLimits&);
extern template Scene<3, float> load_scene<3, float>(const nlohmann::json&, const std::string&,
                                                     const SceneLimits&);
extern template Scene<3, double> load_scene<3, double>(const nlohmann::json&, const std::string&,
                                                       const SceneLimits&);

}  // namespace cellsph
