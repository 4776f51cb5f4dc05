#pragma once
// The section readers of load_scene (internal to scene/). Each NAME_reader.cpp reads one section of
// docs/scenes.md from the scene's top-level reader `r`: it owns the section's keys, their defaults and
// their errors. load_scene (scene.cpp) calls them in the order in which their errors are reported (a
// section may use what the earlier ones set: the time section checks the model, the walls the first
// phase's density and gravity). The types here carry what one section hands to the later ones.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellsph/geometry/shape.hpp"
#include "cellsph/scene/json_reader.hpp"
#include "cellsph/scene/particle_budget.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/initial.hpp"

namespace cellsph::scene_detail {

template <int Dim, class Real>
Vec<Dim, Real> to_vec(const std::vector<double>& v) {
  Vec<Dim, Real> out;
  for (int a = 0; a < Dim; ++a) out[a] = static_cast<Real>(v[static_cast<std::size_t>(a)]);
  return out;
}

template <int Dim>
std::vector<double> filled(double x) {
  return std::vector<double>(static_cast<std::size_t>(Dim), x);
}

// An axis-aligned box read from "min"/"max"; max must exceed min on every axis.
template <int Dim>
struct Aabb {
  std::vector<double> lo, hi;
};

template <int Dim>
Aabb<Dim> read_box(JsonReader& r) {
  Aabb<Dim> b{r.required_vector("min", Dim), r.required_vector("max", Dim)};
  for (int a = 0; a < Dim; ++a)
    if (!(b.hi[static_cast<std::size_t>(a)] > b.lo[static_cast<std::size_t>(a)]))
      r.fail("max", "must exceed min on every axis (axis " + std::to_string(a) + ": max " +
                        std::to_string(b.hi[static_cast<std::size_t>(a)]) + " <= min " +
                        std::to_string(b.lo[static_cast<std::size_t>(a)]) + ")");
  return b;
}

template <int Dim>
bool overlap(const Aabb<Dim>& a, const Aabb<Dim>& b, double tol) {
  for (std::size_t k = 0; k < Dim; ++k)
    if (a.hi[k] <= b.lo[k] + tol || b.hi[k] <= a.lo[k] + tol) return false;
  return true;
}

template <int Dim>
bool inside(const Aabb<Dim>& inner, const Aabb<Dim>& outer, double tol) {
  for (std::size_t k = 0; k < Dim; ++k)
    if (inner.lo[k] < outer.lo[k] - tol || inner.hi[k] > outer.hi[k] + tol) return false;
  return true;
}

// The lattice of `spacing` in a block along each axis (solver/initial.hpp).
template <int Dim>
std::array<LatticeAxis, 3> lattice_of(const Aabb<Dim>& b, double spacing, LatticeFit fit) {
  return cellsph::lattice_of<Dim>(b.lo.data(), b.hi.data(), spacing, fit);
}

// Where a scene's mesh files and motion tables are: beside the scene file, or compiled in for a
// built-in scene.
struct MeshFiles {
  bool builtin = false;
  std::filesystem::path dir;
};

MeshFiles mesh_files_of(const std::string& source);

// What the later sections need from the phases.
struct PhaseTable {
  std::vector<std::string> names;
  std::vector<bool> mass_given;  // phases[k].mass set by the scene
  std::vector<double> mass;      // phases[k].mass: the scene's, or rho0 spacing^Dim

  // The "phase" key of a fluid block: an index or a name of a phase; 0 when absent.
  std::int32_t read_reference(JsonReader& e) const;
};

// The regions the fluid blocks are checked against.
template <int Dim>
struct Regions {
  std::vector<Aabb<Dim>> solids;        // regions fluid must not overlap
  std::vector<std::string> solid_keys;  // their key paths, for messages
  std::optional<Aabb<Dim>> container;   // region fluid must lie in
  std::string container_key;            // the walls' key path when walls make it (box or walls)
  int container_open_axis = -1;         // the walls' open top: no wall on the hi face of this axis
  // Shaped obstacles and containers (boundary.obstacles with "mesh", "sphere" or "cylinder"): fluid
  // particles keep half a spacing outside every obstacle and inside some container.
  std::vector<geometry::Shape> solid_shapes, container_shapes;
  std::vector<std::string> shape_keys;  // key paths of all shapes, for the domain check
  std::vector<geometry::Shape> all_shapes;
  std::vector<double> shape_margins;  // how far each shape's particles reach beyond it
};

// The fluid at t = 0, for the hydrostatic start.
template <int Dim>
struct FluidBlocks {
  std::vector<Aabb<Dim>> blocks;
  std::vector<std::int32_t> phase;  // of each block
  std::vector<std::size_t> key;     // each block's index in /fluids (shaped volumes are numbered there too)
  // The pitch of each block's lattice along each axis: the spacing, or stretched where the spacing does not
  // divide the block (solver/initial.hpp, fluid_lattice_axis).
  std::vector<std::array<double, 3>> pitch;
  // Shaped fluid volumes: their bounds (for the overlap checks), and the particles each made.
  std::vector<Aabb<Dim>> shape_bounds;
  std::vector<std::pair<std::size_t, std::size_t>> shape_ranges;
  std::vector<std::int32_t> shape_phase;
};

// /phases (phases_reader.cpp).
template <int Dim, class Real>
PhaseTable read_phases(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg);

// /solver (solver_reader.cpp). check_model_fits first refuses, in one message, the settings that a scene
// switched to another model keeps and that model refuses, with the --set edits that fit.
void check_model_fits(const nlohmann::json& j, const std::string& source);
template <int Dim, class Real>
void read_solver(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg);

// /time (time_reader.cpp; after the solver: per-particle steps need the paper model).
template <int Dim, class Real>
void read_time(JsonReader& r, SolverConfig<Dim, Real>& cfg, OutputSettings& out);

// /neighbors (neighbors_reader.cpp).
template <int Dim, class Real>
void read_neighbors(JsonReader& r, SolverConfig<Dim, Real>& cfg);
// /parallel (neighbors_reader.cpp).
template <int Dim, class Real>
void read_parallel(JsonReader& r, SolverConfig<Dim, Real>& cfg);

// The shape of an obstacle, body or fluid volume at `e`: "mesh", "sphere" or "cylinder" (docs/scenes.md,
// "Shapes"); nothing when it is a box ("min", "max") (shapes_reader.cpp).
template <int Dim>
std::optional<geometry::Shape> read_shape(JsonReader& e, double spacing, const MeshFiles& files);

// boundary.obstacles[k].motion (docs/scenes.md, "Moving obstacles"; motion_reader.cpp). Returns the
// motion's index in cfg.wall_motion.motions.
template <int Dim, class Real>
std::int32_t read_motion(JsonReader& e, const MeshFiles& files, SolverConfig<Dim, Real>& cfg);

// /boundary: makes the wall and obstacle particles (after the fluid blocks were counted, before they are
// made; boundary_reader.cpp).
template <int Dim, class Real>
Regions<Dim> read_boundary(JsonReader& r, double spacing, const MeshFiles& files,
                           SolverConfig<Dim, Real>& cfg, ParticleBudget& budget, Particles<Dim, Real>& p);

// /bodies and /body_contact: the floating bodies' particles, mass properties and initial state
// (bodies_reader.cpp).
template <int Dim, class Real>
void read_bodies(JsonReader& r, double spacing, const MeshFiles& files, ParticleBudget& budget,
                 Particles<Dim, Real>& p, Regions<Dim>& regions, SolverConfig<Dim, Real>& cfg);

// /domain, and the default domain of a scene without one and without a box (domain_reader.cpp).
template <int Dim, class Real>
void read_domain(JsonReader& r, SolverConfig<Dim, Real>& cfg, Regions<Dim>& regions);
template <int Dim, class Real>
void default_domain(const Particles<Dim, Real>& p, const Inflow& inflow, double spacing,
                    SolverConfig<Dim, Real>& cfg);

// /fluids (fluids_reader.cpp). count_fluid_particles counts the particles the fluid blocks ask for from
// the JSON as it is (before the boundary, as they are most of a scene); a malformed block counts 0 there
// and is reported by read_fluids.
template <int Dim>
double count_fluid_particles(const nlohmann::json& j, double spacing);
template <int Dim, class Real>
FluidBlocks<Dim> read_fluids(JsonReader& r, double spacing, const MeshFiles& files, const PhaseTable& phases,
                             const Regions<Dim>& regions, ParticleBudget& budget, Particles<Dim, Real>& p);

// /initial_pressure: the hydrostatic start's masses and densities (initial_pressure_reader.cpp).
template <int Dim, class Real>
void read_initial_pressure(JsonReader& r, double spacing, const SolverConfig<Dim, Real>& cfg,
                           const PhaseTable& phases, const FluidBlocks<Dim>& fluids, Particles<Dim, Real>& p);

// /solver/eos/stiffness derived from the scene where it leaves it out and its model has a state equation
// (sound_speed_default.cpp): sets cfg.eos.stiffness and says how.
template <int Dim, class Real>
std::optional<DerivedSetting> default_stiffness(const nlohmann::json& j, SolverConfig<Dim, Real>& cfg,
                                                const Particles<Dim, Real>& p);

// /time/dt_column derived from the scene where it leaves it out, for DFSPH and IISPH with Courant steps
// (sound_speed_default.cpp): 0.7 d / sqrt(g H), H as for the stiffness; says how.
template <int Dim, class Real>
std::optional<DerivedSetting> default_column_step(const nlohmann::json& j, double spacing,
                                                  SolverConfig<Dim, Real>& cfg,
                                                  const Particles<Dim, Real>& p);

// Geometry the spacing resolves poorly (geometry_warnings.cpp): a gap narrower than two spacings between two
// obstacles (boxes or shapes) or an obstacle and the tank's walls, an obstacle thinner than the kernel
// support. One sentence each, naming the keys; nothing is changed.
template <int Dim>
std::vector<std::string> geometry_warnings(const Regions<Dim>& regions, double spacing, double support);
// Fluid blocks thinner than the kernel support along some axis (geometry_warnings.cpp): one sentence each.
template <int Dim>
std::vector<std::string> fluid_block_warnings(const FluidBlocks<Dim>& fluids, double support);

// How deep inside a wall or obstacle a fluid particle may end a step, and how far on the fluid side of
// its surface it is put back, in spacings (solver/boundary/solid_guard.hpp): the first layer of wall
// particles, and the surface itself.
inline constexpr double kGuardDepth = 0.5;
inline constexpr double kGuardMargin = 0.0;

// How far from a shaped solid's surface the solid guard's grid holds exact distances, in spacings.
inline constexpr double kGuardGridBand = 3.0;

// Adds shaped solid `shape` to the solid guard (solid_guard_grid.cpp): its signed distance on a grid of
// one spacing's pitch over its bounds grown by kGuardGridBand spacings, positive on the fluid's side
// (outside, or inside a `container`), moved by `mover`.
template <int Dim, class Real>
void add_guard_grid(const geometry::Shape& shape, double spacing, bool container, GuardMover mover,
                    SolidGuard<Dim, Real>& guard);

// /output, and the box drawn in pictures (output_reader.cpp).
template <int Dim>
void read_output(JsonReader& r, OutputSettings& out);
template <int Dim, class Real>
void set_view(Scene<Dim, Real>& s, const std::optional<Aabb<Dim>>& container);

// /probes and /probes_every (probes_reader.cpp).
template <int Dim>
void read_probes(JsonReader& r, std::vector<Probe>& probes, double& every);

}  // namespace cellsph::scene_detail
