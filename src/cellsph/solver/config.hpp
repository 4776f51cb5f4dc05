#pragma once
// Everything a run of the solver needs to know, as plain data. Scene files fill it; validate() names the
// key and the value of the first bad entry (InputError -> exit 2).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/core/vec.hpp"
#include "cellsph/neighbors/neighbor_list.hpp"
#include "cellsph/physics/eos.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/backend.hpp"
#include "cellsph/solver/boundary/rigid_bodies.hpp"
#include "cellsph/solver/boundary/wall_motion.hpp"
#include "cellsph/solver/emitters.hpp"

namespace cellsph {

// Which SPH model a step runs.
enum class Model {
  PaperMultiphase,  // Onderik & Durikovic 2007, Algorithm 1: eq. 7-9, leap-frog eq. 11
  Wcsph,            // the CUDA write-up: operator splitting, symmetric pressure, symplectic Euler
  Dfsph,            // Bender & Koschier 2015/2017: divergence-free SPH, implicit pressure (models/dfsph.hpp)
  Iisph,            // Ihmsen et al. 2014: implicit incompressible SPH, relaxed Jacobi (models/iisph.hpp)
};

// The models whose pressure is solved for (DFSPH and IISPH): they share the DFSPH passes, the settings
// SolverConfig::dfsph, the Akinci walls and the run's solver statistics.
constexpr bool implicit_pressure(Model m) {
  return m == Model::Dfsph || m == Model::Iisph;
}

// How the paper's model obtains densities of neighbours of another phase.
enum class DensityFormulation {
  Mass,    // eq. 7: rho_i = sum_j m_j W_ij (smears densities across a density jump)
  Number,  // Solenthaler & Pajarola 2008: delta_i = sum_j W_ij, rho_i = m_i delta_i, V_i = 1 / delta_i
};

// How the paper's model turns the colour field into interface tension.
enum class TensionModel {
  Paper,  // eq. 9: f = -sigma lap C grad C / |grad C| (Algorithm 1, lines 11-14)
  // Continuum surface force with the curvature from the divergence of the unit normal (Brackbill 1992,
  // in SPH as Morris 2000): n = sum_j V_j (c_j - c_i) grad W, kappa = -div(n / |n|), f = sigma kappa n.
  Csf,
  // Akinci et al. 2013, within each phase: pairwise cohesion -gamma m_i m_j C(r) x_ij / r and curvature
  // -gamma m (n_i - n_j) with n_i = h sum_j V_j grad W_ij, both scaled by 2 rho0 / (rho_i + rho_j);
  // sigma of the phase is gamma. Every term is antisymmetric in (i, j): momentum is conserved, so a free
  // drop does not propel itself as it does under eq. 9 (whose force does not sum to zero). Acts at free
  // surfaces too (CSF's difference-form normals vanish there); gamma is a model coefficient, not the
  // physical surface tension.
  Akinci,
};

// How the WCSPH model obtains fluid densities (scene key solver.density).
enum class DensityEvolution {
  Summation,   // rho_i = sum_j m_j W_ij each step (models/summation_density.hpp)
  Continuity,  // d rho_i / dt = sum_j m_j (v_i - v_j) . grad W_ij, integrated (models/continuity_density.hpp)
};

// Density diffusion added to the continuity equation (delta-SPH; models/continuity_density.hpp).
enum class DensityDiffusion {
  None,
  Molteni,    // Molteni & Colagrossi 2009: delta h c0 times the SPH Laplacian of rho
  Fourtakas,  // Fourtakas et al. 2019: the same on rho minus its hydrostatic part
};

// A wall particle's pressure in DFSPH's pressure force (SolverConfig::Dfsph::wall_pressure).
enum class DfsphWallPressure {
  Zero,         // "zero": 0, Akinci 2012 as SPlisHSPlasH
  Mirrored,     // "mirrored": the fluid particle's own
  Hydrostatic,  // "hydrostatic": the fluid particle's own plus rho_i (g - a_b) . (x_b - x_i)
};

// DFSPH's constant-density solve (SolverConfig::Dfsph::density_solver).
enum class DfsphDensitySolver {
  Jacobi,             // "jacobi": the sweeps of Bender & Koschier (models/dfsph.hpp)
  ConjugateGradient,  // "cg": preconditioned CG on the active set (models/dfsph_cg.hpp)
};

enum class TimeStepping {
  Fixed,    // dt = time.dt every step (the paper's test)
  Courant,  // global dt = min over particles of eq. 12, the viscous and the force limit, at most dt_max
  // Per-particle power-of-two steps (Desbrun 1996; eq. 12-13): particle i advances with dt_max / 2^n_i
  // and is integrated only when the global clock reaches its own time. Paper model only.
  PerParticle,
};

// What happens when a particle's step changes from dt_old to dt_new.
enum class StepChangeCorrection {
  // Variable-step leap-frog: the kick uses (dt_old + dt_new)/2, which lands the stored velocity on the
  // new half step; exact under a constant force, no position correction needed.
  Exact,
  // Algorithm 1's kick v += dt_new f/m with eq. 13 as printed: r += (dt_new^2 - dt_old^2) / (8 m) f.
  Printed,
};

// How boundary particles (walls, obstacles) take part in the forces on fluid particles.
enum class WallModel {
  // Akinci et al. 2012: per pair, the wall mirrors the fluid particle's density and its pressure
  // extrapolated hydrostatically from it; no slip: viscosity against a wall at rest.
  Akinci,
  // Adami, Hu & Adams 2012: each wall particle gets one pressure per step, the kernel average of its
  // fluid neighbours' pressures plus the hydrostatic term (their eq. 27), its density from that pressure
  // through the equation of state, and for no slip the velocity 2 v_wall - (kernel average of the fluid
  // velocities) (their eq. 22-23); the fluid-wall forces are then ordinary symmetric pair terms.
  // p_w is not a function of the wall's own kernel-sampled density, so its force is not the gradient of
  // an energy: in a weakly viscous closed box it does net positive work (docs/physics.md).
  Adami,
  // Dynamic boundary particles (Crespo, Gomez-Gesteira & Dalrymple 2007), with summation density: each wall
  // particle is a fluid particle held at rest, rho_w = sum_k m_k W_wk over its fluid and wall neighbours
  // (itself included) and p_w = EOS(rho_w); the pair forces are the fluid's. Forces are then minus the
  // gradient of the total internal energy, fluid and walls (Monaghan 2005's Lagrangian with the wall
  // positions fixed), so walls do no net work. No slip: viscosity against a wall at rest.
  Dynamic,
  // No wall particles: every solid of SolidGuard (the tank, boxes, shapes) is one map on a grid
  // (boundary/bender2019.hpp, after Bender et al. 2019's volume maps): at each fluid particle the walls'
  // kernel integral D = int_solid W, its gradient and the solid's share of the support ball, which the
  // implicit models' density, solves and forces take as one wall neighbour. DFSPH and IISPH, static solids.
  VolumeMap,
};

// One fluid (or boundary material): the phases table of a scene.
template <class Real>
struct Phase {
  std::string name = "water";
  Real rest_density = 1000;  // rho0 [kg/m^3]
  Real mass = 0;             // particle mass [kg]; 0: rest_density * spacing^Dim where the scene fills blocks
  Real viscosity = 0;        // dynamic viscosity mu [Pa s]
  Real color = 1;            // interface colour value c^int (eq. 8c)
  Real sigma = 0;            // interface / surface tension coefficient (eq. 9)
};

// A half-space wall: the fluid side is dot(normal, x) >= offset (normal of unit length, into the fluid).
template <int Dim, class Real>
struct Plane {
  Vec<Dim, Real> normal{};
  Real offset = 0;
};

// Where a moving solid is now (boundary/solid_guard.hpp): a point of it that was at x_rest in the scene is
// at R x_rest + b, moving at u + w x (x - c). Double precision, 3 components (z = 0 and w along z in 2D).
struct GuardFrame {
  double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // row major
  double b[3] = {0, 0, 0};
  double c[3] = {0, 0, 0};
  double u[3] = {0, 0, 0};
  double w[3] = {0, 0, 0};
};

// Which frame moves a guarded solid: a prescribed motion (WallMotions::motions), a floating body
// (RigidBodies::bodies), or none (at rest). The frames are the motions' first, then the bodies'.
struct GuardMover {
  std::int32_t motion = -1;
  std::int32_t body = -1;
  [[nodiscard]] CELLSPH_HD std::int32_t frame(std::int32_t motions) const {
    return motion >= 0 ? motion : (body >= 0 ? motions + body : -1);
  }
  [[nodiscard]] bool moves() const { return motion >= 0 || body >= 0; }
};

// A box obstacle or box body that the solid guard keeps the fluid out of (boundary/solid_guard.hpp),
// where the scene placed it.
template <int Dim, class Real>
struct GuardBox {
  Vec<Dim, Real> lo{}, hi{};
  GuardMover mover{};
};

// A shaped solid (sphere, cylinder, mesh; obstacle, container or body) as its signed distance on a grid
// of nodes origin + pitch (i, j, k), where the scene placed it: the values (SolidGuard::grid_values,
// from `first`, x fastest) are positive on the fluid's side (outside a solid, inside a container) and
// clamped to +-band. A point off the grid is on the fluid's side of a solid and deep in a container's.
template <int Dim, class Real>
struct GuardGrid {
  Vec<Dim, Real> origin{};
  Real pitch = 0;
  Real band = 0;
  std::int32_t n[3] = {1, 1, 1};
  std::uint64_t first = 0;
  bool container = false;
  GuardMover mover{};
};

// The solids no fluid particle may end a step inside (boundary/solid_guard.hpp): the tank of
// boundary.walls, the box and shaped obstacles, containers and bodies, and the distance kept from their
// surfaces.
template <int Dim, class Real>
struct SolidGuard {
  bool container = false;  // boundary.walls: the fluid stays inside [lo, hi]
  Vec<Dim, Real> lo{}, hi{};
  int open_axis = -1;  // the open top: no wall on the hi face of this axis; -1: closed
  std::vector<GuardBox<Dim, Real>> boxes{};
  std::vector<GuardGrid<Dim, Real>> grids{};
  std::vector<Real> grid_values{};
  Real depth = 0;   // how deep inside a solid a particle may end a step [m]
  Real margin = 0;  // how far on the fluid side of the surface it is put back [m]
  [[nodiscard]] bool any() const { return container || !boxes.empty() || !grids.empty(); }
  [[nodiscard]] bool moving() const {
    for (const auto& b : boxes)
      if (b.mover.moves()) return true;
    for (const auto& g : grids)
      if (g.mover.moves()) return true;
    return false;
  }
};

// The solids as a volume map (WallModel::VolumeMap; boundary/bender2019.hpp builds and reads it). The
// walls' kernel sums are those of the fluid's lattice continued into the solid in layers: the half-space's
// profile (per entry kProfileColumns values at signed distance d in [-reach, reach], a step
// `profile_step` apart); for the tank, exactly, its faces' profiles less their edges' and corners' overlaps
// (tables over [-reach, reach]^2 and ^3, `table_count` entries per axis, each value and its derivative in
// the first distance); the other solids (boxes, shapes) on a grid of nodes origin + pitch (i, j, k), x
// fastest, each with kFields values: the equivalent distance (where a half-space has their D), its
// gradient, and the difference of their F from the half-space's there. Built by the Simulation from the
// SolidGuard when empty.
template <int Dim, class Real>
struct VolumeMap {
  static constexpr int kFields = 2 + Dim;    // equivalent distance, its gradient, F's difference
  static constexpr int kProfileColumns = 5;  // D, dD/dd, F, T's normal and tangential parts
  bool built = false;
  Real reach = 0;  // the kernel's support h: no solid acts on a particle farther than this
  Real profile_step = 0;
  std::vector<Real> profile{};
  bool tank = false;
  Vec<Dim, Real> lo{}, hi{};
  int open_axis = -1;
  std::int32_t table_count[2] = {0, 0};  // the edge (two faces) and corner (three faces) tables
  std::vector<Real> edge{}, corner{};
  Vec<Dim, Real> origin{};
  Real pitch = 0;
  std::int32_t n[3] = {1, 1, 1};
  std::vector<Real> nodes{};
  [[nodiscard]] bool empty() const { return !built; }
};

template <int Dim, class Real>
struct SolverConfig {
  using V = Vec<Dim, Real>;

  Model model = Model::PaperMultiphase;
  // Where the steps run (backend.hpp; scene key solver.backend, `--backend`): the Simulation moves its
  // particles to a device at construction when this is not Cpu.
  Backend backend = Backend::Cpu;

  // Kernels. Density uses `density_kernel` (the paper: poly6), pressure the gradient of `pressure_kernel`
  // (the paper: spiky); the WCSPH model also uses that gradient in the laminar (Morris) and artificial
  // (Monaghan) viscosities. The paper's viscosity (eq. 8b) always uses the viscosity kernel's Laplacian,
  // whose positivity it relies on, and the colour field always uses poly6 (eq. 8c).
  KernelKind density_kernel = KernelKind::Poly6;
  KernelKind pressure_kernel = KernelKind::Spiky;
  Real support = Real(0.05);  // h [m]: kernel support and neighbour radius (paper eq. 14)
  DensityFormulation density = DensityFormulation::Mass;

  EquationOfState<Real> eos{};
  std::vector<Phase<Real>> phases{Phase<Real>{}};

  // WCSPH only: summation density or the continuity equation, with density diffusion (continuity only).
  // `delta` is the dimensionless coefficient of the diffusion term delta h c0 lap(rho) (0.1 in both papers),
  // h the smoothing length support / 2.
  DensityEvolution density_evolution = DensityEvolution::Summation;
  struct Diffusion {
    DensityDiffusion kind = DensityDiffusion::None;
    Real delta = Real(0.1);
  } density_diffusion{};
  // WCSPH only: Monaghan's (1992) artificial viscosity, alpha (dimensionless) with the sound speed c0 and
  // the smoothing length support / 2, acting on approaching pairs only; off (alpha 0) by default, and not
  // between fluid and wall particles unless `walls` (engineering codes leave it off there).
  struct ArtificialViscosity {
    Real alpha = 0;
    bool walls = false;
  } artificial_viscosity{};

  // |grad C| below which no interface tension acts (Mueller 2003's threshold l; the write-up's 7.065).
  Real tension_threshold = 0;
  TensionModel tension = TensionModel::Paper;
  V gravity = gravity_default();

  struct Time {
    TimeStepping mode = TimeStepping::Fixed;
    Real dt = Real(0.002);     // Fixed: the step [s]
    Real dt_max = Real(0.01);  // Courant: upper bound of the step [s]
    // DFSPH and IISPH with Courant steps: also at most this [s] (0: no such bound). Scenes derive it as
    // 0.7 d / sqrt(g H), the longest step a resting column H deep holds (scene/sound_speed_default.cpp).
    Real dt_column = Real(0);
    Real courant = Real(0.3);    // alpha of eq. 12
    Real viscous = Real(0.125);  // dt <= viscous * h^2 rho0 / mu
    Real force = Real(0.25);     // dt <= force * sqrt(h / |a|max)
    int max_level = 12;          // PerParticle: finest step dt_max / 2^max_level
    StepChangeCorrection correction = StepChangeCorrection::Exact;
  } time{};

  // The write-up's box: a particle that leaves [lo + r, hi - r] is put back on the wall and its normal
  // velocity multiplied by `damping` (the write-up's BoundaryDamping = -0.5).
  struct Box {
    bool enabled = false;
    V lo{}, hi{};
    Real damping = Real(-0.5);
    Real radius = 0;  // particle radius kept from the wall
  } box{};

  // The paper's walls (section 5): inelastic collision with restitution e, wet friction (tangential velocity
  // reduced by a fixed fraction per contact, not by the normal impulse as dry Coulomb friction would) and
  // projection of the particle back onto the wall to prevent overshooting.
  std::vector<Plane<Dim, Real>> planes{};
  // Boundary particles (walls, obstacles): free slip (pressure only) or no slip (also the fluid
  // particle's viscosity against a wall at rest, as between two fluid particles).
  bool no_slip = false;
  WallModel wall_model = WallModel::Akinci;
  // Fluid particles put back out of the walls and obstacles they would end a step inside.
  SolidGuard<Dim, Real> guard{};
  // WallModel::VolumeMap: the guard's solids as a map (built from `guard` when empty).
  VolumeMap<Dim, Real> volume_map{};
  // Moving walls (boundary/wall_motion.hpp; scene key boundary.obstacles[k].motion): the prescribed
  // motions and which boundary particle each moves. Empty: every wall at rest. CPU steps only.
  WallMotions wall_motion{};
  // Floating bodies (boundary/rigid_bodies.hpp; scene key bodies): their mass, inertia and initial state
  // and which boundary particle belongs to which. Empty: none. WCSPH with global steps on the CPU only.
  RigidBodies rigid_bodies{};
  // Inflow and outflow (emitters.hpp; scene keys emitters, sinks): particle counts change during the run.
  // CPU, global steps only.
  Inflow inflow{};
  Real restitution = Real(0.2);
  Real friction = Real(0.1);

  // Particles outside this box (grown by one support length) stop the run as unstable. If not set, the
  // box above is used when enabled, otherwise the escape test is off. A scene without /domain or a box
  // gets a default one (scene/domain_reader.cpp, default_domain; domain_default says so in the diagnosis).
  bool domain_set = false;
  bool domain_default = false;
  V domain_lo{}, domain_hi{};

  // Model::Dfsph (models/dfsph.hpp). Errors in percent, as SPlisHSPlasH takes them: the average density
  // error of the constant-density solver in % of the rest density, the average divergence error of the
  // divergence-free solver in % of the rest density per step. min_iterations is the constant-density
  // solver's minimum (the divergence-free solver makes at least one sweep); both stop at max_iterations.
  // Model::Iisph reads the same settings for its one solve (max_density_error, the iteration bounds, the
  // warm start, wall_pressure) and `relaxation`; the scene gives them as /solver/iisph.
  struct Dfsph {
    Real max_density_error = Real(0.05);
    Real max_divergence_error = Real(0.1);
    int min_iterations = 2;
    int max_iterations = 100;
    bool warm_start = true;
    // The share of the last step's k the constant-density solve starts from (with warm_start; the
    // divergence solve keeps 0.5). 0.5, as SPlisHSPlasH: the Jacobi sweeps only add pressure, so a larger
    // share that overshoots stays for the step; the CG solve takes pressure back (docs/physics.md).
    Real warm_start_scale = Real(0.5);
    DfsphDensitySolver density_solver = DfsphDensitySolver::Jacobi;
    // A wall particle's pressure in the pressure force (`wall_pressure`): 0 ("zero", Akinci 2012 as
    // SPlisHSPlasH: the fluid row next to a wall then carries the column on half the terms, and its
    // pressure is ~1.8x rho0 g d); the fluid particle's own ("mirrored": extrapolated at zeroth order, that
    // row ~6% over rho0 g d); or that plus the hydrostatic rise to the wall particle,
    // rho_i (g - a_b) . (x_b - x_i) ("hydrostatic", Adami's extrapolation, a_b a moving wall's acceleration,
    // applied once a step with the non-pressure forces).
    DfsphWallPressure wall_pressure = DfsphWallPressure::Zero;
    // Model::Iisph only: the relaxation omega of its Jacobi iteration (Ihmsen et al. 2014: 0.5).
    Real relaxation = Real(0.5);
    bool mirror_walls() const { return wall_pressure != DfsphWallPressure::Zero; }
  } dfsph{};

  SearchOptions search{};
  // Verlet lists: the search runs at h (1 + verlet_skin) and its lists are kept until a particle has moved
  // 0.45 of the skin. 0: a search every step. Results do not depend on it (pairs are re-filtered at h).
  // Scenes with /solver/model = "dfsph" default to 0 (scene/solver_reader.cpp, read_solver).
  Real verlet_skin = Real(0.15);
  // Every this many steps the fluid particles' arrays are permuted into cell order (Z-order of cells of
  // size h, ties by id), so that neighbours sit near each other in memory; 0: never (input order kept).
  // Off by default: on the 3D dam break at 10^5 it cost 7-12% while the fluid still holds its input
  // lattice order and gained 1-4% after the impact (docs/benchmarks.md).
  // With per-particle steps: whenever the clock reaches a multiple of reorder_every * dt_max, where
  // every particle is due. Results depend on it only through summation order (last bits), never on
  // the method, skin or thread count; the id field keeps each particle's identity.
  std::uint32_t reorder_every = 0;
  // A run across MPI ranks (docs/distributed.md): when the domain is rebuilt and the busiest rank's work
  // (its fluid particles' neighbour pairs, plus four a particle, plus one a wall particle) exceeds the
  // ranks' mean by more than this fraction, the curve is cut again by the measured work. Scene key
  // /parallel/rebalance_threshold.
  double rebalance_threshold = 0.1;
  std::uint64_t seed = 1;

  static constexpr V gravity_default() {
    V g{};
    g[Dim - 1] = Real(-9.81);
    return g;
  }

  // Throws InputError naming the key and value of the first invalid entry.
  void validate() const;
};

std::string_view model_name(Model m);
std::optional<Model> parse_model(std::string_view name);
std::string_view time_stepping_name(TimeStepping t);
std::optional<TimeStepping> parse_time_stepping(std::string_view name);
std::string_view tension_model_name(TensionModel t);
std::optional<TensionModel> parse_tension_model(std::string_view name);
std::string_view correction_name(StepChangeCorrection c);
std::optional<StepChangeCorrection> parse_correction(std::string_view name);
std::string_view wall_model_name(WallModel w);
std::optional<WallModel> parse_wall_model(std::string_view name);
std::string_view density_formulation_name(DensityFormulation d);
std::string_view density_diffusion_name(DensityDiffusion d);
std::optional<DensityDiffusion> parse_density_diffusion(std::string_view name);
std::optional<DensityFormulation> parse_density_formulation(std::string_view name);

extern template struct SolverConfig<2, float>;
extern template struct SolverConfig<2, double>;
extern template struct SolverConfig<3, float>;
extern template struct SolverConfig<3, double>;

}  // namespace cellsph
