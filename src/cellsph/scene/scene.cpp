// Reading a scene: its JSON (a built-in scene or a file), its header, and load_scene, which calls the
// section readers (NAME_reader.cpp, scene_readers.hpp) in the order in which their errors are reported.
#include "cellsph/scene/scene.hpp"

#include <filesystem>

#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/inflow_reader.hpp"
#include "cellsph/scene/json_reader.hpp"
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph {

nlohmann::json read_scene_json(const std::string& name_or_path, std::string& source) {
  for (const auto& s : builtin_scenes()) {
    if (s.name == name_or_path) {
      source = "built-in scene " + std::string(s.name);
      try {
        return nlohmann::json::parse(s.json);
      } catch (const nlohmann::json::parse_error& e) {
        throw InputError(source + ": invalid JSON: " + e.what());
      }
    }
  }
  const std::filesystem::path p(name_or_path);
  if (!std::filesystem::exists(p)) {
    std::string names;
    for (const auto& s : builtin_scenes()) names += (names.empty() ? "" : ", ") + std::string(s.name);
    throw InputError("'" + name_or_path + "' is neither a built-in scene (" + names +
                     ") nor an existing scene file");
  }
  source = p.string();
  return JsonReader::parse_file(p);
}

SceneHeader read_scene_header(const nlohmann::json& j, const std::string& source) {
  if (!j.is_object())
    throw InputError(source + ": /: a scene must be a JSON object, got " + json_value_text(j));
  JsonReader r(j, source, "");
  SceneHeader h;
  h.name = r.string("name", "scene");
  if (h.name.empty()) r.fail("name", "must not be empty");
  for (char c : h.name)
    if (c == '/' || c == '\\') r.fail("name", "must not contain a path separator, got \"" + h.name + "\"");
  h.description = r.string("description", "");
  h.dim = static_cast<int>(r.integer("dimension", 2, 2, 3));
  h.single_precision = r.choice("precision", "double", {"double", "float"}) == "float";
  return h;
}

template <int Dim, class Real>
Scene<Dim, Real> load_scene(const nlohmann::json& j, const std::string& source, const SceneLimits& limits) {
  using namespace scene_detail;
  Scene<Dim, Real> s;
  s.header = read_scene_header(j, source);
  s.source = source;
  CELLSPH_CHECK(s.header.dim == Dim, "scene dimension " << s.header.dim << " loaded as " << Dim);
  JsonReader r(j, source, "");
  // The header keys were checked by read_scene_header; mark them read here.
  r.string("name", "");
  r.string("description", "");
  r.integer("dimension", 2, 2, 3);
  r.string("precision", "");

  const double spacing = r.required_number("spacing", 1e-9, 1e9);
  s.spacing = static_cast<Real>(spacing);
  auto& cfg = s.solver;
  const PhaseTable phases = read_phases(r, spacing, cfg);
  check_model_fits(j, source);
  read_solver(r, spacing, cfg);
  read_time(r, cfg, s.output);
  read_neighbors(r, cfg);
  read_parallel(r, cfg);

  // Particles: counted (fluid blocks first) before each is made, boundary before fluid.
  ParticleBudget budget(Dim, spacing, double(cfg.support) * (1 + double(cfg.verlet_skin)) / spacing,
                        limits.memory_bytes);
  budget.take(count_fluid_particles<Dim>(j, spacing), r, "fluids", "the fluid blocks");
  const MeshFiles files = mesh_files_of(source);
  Regions<Dim> regions = read_boundary(r, spacing, files, cfg, budget, s.particles);
  read_bodies(r, spacing, files, budget, s.particles, regions, cfg);
  read_domain(r, cfg, regions);
  s.warnings = geometry_warnings(regions, spacing, double(cfg.support));
  const FluidBlocks<Dim> fluids = read_fluids(r, spacing, files, phases, regions, budget, s.particles);
  for (auto& w : fluid_block_warnings(fluids, double(cfg.support))) s.warnings.push_back(std::move(w));
  if (auto d = default_stiffness(j, cfg, s.particles)) s.derived.push_back(std::move(*d));
  if (auto d = default_column_step(j, spacing, cfg, s.particles)) s.derived.push_back(std::move(*d));
  read_initial_pressure(r, spacing, cfg, phases, fluids, s.particles);
  read_inflow(
      r, Dim, spacing, [&phases](JsonReader& e) { return phases.read_reference(e); }, cfg.inflow);
  // Moving obstacles: every particle after the last moving one (fluid, other walls) is at rest.
  if (cfg.wall_motion.any()) cfg.wall_motion.of_particle.resize(s.particles.size(), -1);
  if (cfg.rigid_bodies.any()) cfg.rigid_bodies.of_particle.resize(s.particles.size(), -1);
  default_domain(s.particles, cfg.inflow, spacing, cfg);

  read_output<Dim>(r, s.output);
  read_probes<Dim>(r, s.probes, s.probes_every);
  r.finish();
  set_view(s, regions.container);

  try {
    cfg.validate();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return s;
}

template Scene<2, float> load_scene<2, float>(const nlohmann::json&, const std::string&, const SceneLimits&);
template Scene<2, double> load_scene<2, double>(const nlohmann::json&, const std::string&,
                                                const SceneLimits&);
template Scene<3, float> load_scene<3, float>(const nlohmann::json&, const std::string&, const SceneLimits&);
template Scene<3, double> load_scene<3, double>(const nlohmann::json&, const std::string&,
                                                const SceneLimits&);

}  // namespace cellsph
