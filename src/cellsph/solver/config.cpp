#include "cellsph/solver/config.hpp"

#include <cmath>
#include <sstream>

#include "cellsph/core/error.hpp"

namespace cellsph {

namespace {
template <class T>
[[noreturn]] void bad(const std::string& key, const T& value, const char* why) {
  std::ostringstream os;
  os << "solver config: " << key << " = " << value << ": " << why;
  throw InputError(os.str());
}
template <class Real>
void positive(const std::string& key, Real v) {
  if (!(std::isfinite(v) && v > 0)) bad(key, v, "must be a finite number > 0");
}
template <class Real>
void non_negative(const std::string& key, Real v) {
  if (!(std::isfinite(v) && v >= 0)) bad(key, v, "must be a finite number >= 0");
}
// The numbers: support, equation of state, phases, gravity and time-step settings.
template <int Dim, class Real>
void validate_numbers(const SolverConfig<Dim, Real>& c) {
  positive("support", c.support);
  positive("eos.stiffness", c.eos.stiffness);
  if (c.eos.kind == EosKind::Tait) positive("eos.gamma", c.eos.gamma);
  if (c.phases.empty()) bad("phases", "[]", "at least one phase is needed");
  for (std::size_t k = 0; k < c.phases.size(); ++k) {
    const std::string p = "phases[" + std::to_string(k) + "].";
    positive(p + "rest_density", c.phases[k].rest_density);
    non_negative(p + "mass", c.phases[k].mass);
    non_negative(p + "viscosity", c.phases[k].viscosity);
    if (!std::isfinite(c.phases[k].color)) bad(p + "color", c.phases[k].color, "must be finite");
    non_negative(p + "sigma", c.phases[k].sigma);
  }
  non_negative("tension_threshold", c.tension_threshold);
  non_negative("verlet_skin", c.verlet_skin);
  for (int a = 0; a < Dim; ++a)
    if (!std::isfinite(c.gravity[a]))
      bad("gravity[" + std::to_string(a) + "]", c.gravity[a], "must be finite");
  positive("time.dt", c.time.dt);
  positive("time.dt_max", c.time.dt_max);
  non_negative("time.dt_column", c.time.dt_column);
  if (!(c.rebalance_threshold > 0 && c.rebalance_threshold <= 10))
    throw InputError("parallel.rebalance_threshold: " + std::to_string(c.rebalance_threshold) +
                     " (a fraction of the mean work, above 0 and at most 10)");
  positive("time.courant", c.time.courant);
  positive("time.viscous", c.time.viscous);
  positive("time.force", c.time.force);
  if (c.time.max_level < 0 || c.time.max_level > 40)
    bad("time.max_level", c.time.max_level, "must be in [0, 40]");
}

// The settings that need the paper model or global steps.
template <int Dim, class Real>
void validate_model_fit(const SolverConfig<Dim, Real>& c) {
  if (c.tension != TensionModel::Paper && c.model != Model::PaperMultiphase)
    bad("tension", tension_model_name(c.tension),
        "the WCSPH model has the write-up's Mueller tension; csf and akinci need the paper model (model = "
        "paper)");
  if (c.time.mode == TimeStepping::PerParticle && c.model != Model::PaperMultiphase)
    bad("time.mode", "per-particle", "per-particle steps need the paper model's leap-frog (model = paper)");
  // Wall states are computed from all fluid densities of a step; a per-particle sub-step has only some.
  if (c.wall_model != WallModel::Akinci && c.time.mode == TimeStepping::PerParticle)
    bad("boundary.model", wall_model_name(c.wall_model),
        "needs global steps (time.mode fixed or courant), not per-particle");
}

// The write-up's box and the paper's planes.
template <int Dim, class Real>
void validate_collisions(const SolverConfig<Dim, Real>& c) {
  if (c.box.enabled) {
    for (int a = 0; a < Dim; ++a)
      if (!(c.box.hi[a] - 2 * c.box.radius > c.box.lo[a]))
        bad("box.hi[" + std::to_string(a) + "]", c.box.hi[a], "must exceed box.lo + 2 radius");
    non_negative("box.radius", c.box.radius);
    if (!(c.box.damping <= 0 && c.box.damping >= -1)) bad("box.damping", c.box.damping, "must be in [-1, 0]");
  }
  for (std::size_t k = 0; k < c.planes.size(); ++k) {
    const Real n2 = norm2(c.planes[k].normal);
    if (!(std::abs(n2 - 1) < Real(1e-3)))
      bad("planes[" + std::to_string(k) + "].normal", std::sqrt(n2), "must have unit length");
  }
  if (!(c.restitution >= 0 && c.restitution <= 1)) bad("restitution", c.restitution, "must be in [0, 1]");
  if (!(c.friction >= 0 && c.friction <= 1)) bad("friction", c.friction, "must be in [0, 1]");
}

// Density evolution, density diffusion and artificial viscosity, and the models they need.
template <int Dim, class Real>
void validate_density(const SolverConfig<Dim, Real>& c) {
  if (c.density_evolution == DensityEvolution::Continuity && c.model != Model::Wcsph)
    bad("density", "continuity", "the continuity equation needs the WCSPH model (model = wcsph)");
  if (c.density_diffusion.kind != DensityDiffusion::None) {
    if (c.density_evolution != DensityEvolution::Continuity)
      bad("density_diffusion.kind", density_diffusion_name(c.density_diffusion.kind),
          "diffuses an integrated density: needs density = continuity");
    if (!(std::isfinite(c.density_diffusion.delta) && c.density_diffusion.delta >= 0 &&
          c.density_diffusion.delta <= 1))
      bad("density_diffusion.delta", c.density_diffusion.delta, "must be in [0, 1]");
  }
  if (!(std::isfinite(c.artificial_viscosity.alpha) && c.artificial_viscosity.alpha >= 0 &&
        c.artificial_viscosity.alpha <= 10))
    bad("artificial_viscosity.alpha", c.artificial_viscosity.alpha, "must be in [0, 10]");
  if (c.artificial_viscosity.alpha > 0 && c.model != Model::Wcsph)
    bad("artificial_viscosity.alpha", c.artificial_viscosity.alpha,
        "artificial viscosity is part of the WCSPH model (model = wcsph)");
}

// DFSPH and IISPH: their solves' settings and what they do not support.
template <int Dim, class Real>
void validate_implicit(const SolverConfig<Dim, Real>& c) {
  if (!implicit_pressure(c.model)) return;
  // IISPH's settings are SolverConfig::dfsph too; its messages name them as the scene does (iisph.*).
  const std::string sec = c.model == Model::Iisph ? "iisph." : "dfsph.";
  const std::string name = c.model == Model::Iisph ? "IISPH" : "DFSPH";
  positive(sec + "max_density_error", c.dfsph.max_density_error);
  if (c.model == Model::Dfsph) positive("dfsph.max_divergence_error", c.dfsph.max_divergence_error);
  if (c.dfsph.min_iterations < 0) bad(sec + "min_iterations", c.dfsph.min_iterations, "must be >= 0");
  if (c.dfsph.max_iterations < 1) bad(sec + "max_iterations", c.dfsph.max_iterations, "must be >= 1");
  if (c.dfsph.min_iterations > c.dfsph.max_iterations)
    bad(sec + "min_iterations", c.dfsph.min_iterations,
        ("must not exceed " + sec + "max_iterations = " + std::to_string(c.dfsph.max_iterations)).c_str());
  if (!(c.dfsph.warm_start_scale > 0 && c.dfsph.warm_start_scale <= 1))
    bad(sec + "warm_start_scale", c.dfsph.warm_start_scale, "must be in (0, 1]");
  if (c.model == Model::Iisph && !(c.dfsph.relaxation > 0 && c.dfsph.relaxation <= 1))
    bad("iisph.relaxation", c.dfsph.relaxation, "must be in (0, 1]");
  if (c.model == Model::Iisph && c.dfsph.density_solver != DfsphDensitySolver::Jacobi)
    bad("dfsph.density_solver", "cg", "IISPH's solve is its relaxed Jacobi iteration");
  // Several phases: the number density's system is not symmetric in k (its pair force weighs m_i^2 k_i
  // and m_j^2 k_j), which CG needs.
  if (c.dfsph.density_solver == DfsphDensitySolver::ConjugateGradient &&
      c.density == DensityFormulation::Number)
    bad("dfsph.density_solver", "cg",
        "the conjugate-gradient solve needs the mass density of one phase; several phases (density = "
        "number) take \"jacobi\"");
  // Adami and dynamic walls take their pressure from the fluid's (extrapolated) or from an equation of
  // state; neither is an unknown of the DFSPH solves, so the factor alpha_i would not describe what a
  // sweep changes (docs/physics.md, "DFSPH").
  if (c.wall_model != WallModel::Akinci && c.wall_model != WallModel::VolumeMap)
    bad("boundary.model", wall_model_name(c.wall_model),
        ("the " + name +
         " model takes Akinci 2012 boundary particles or volume maps (boundary.model = "
         "akinci or volume-map)")
            .c_str());
  for (std::size_t k = 0; k < c.phases.size(); ++k)
    if (c.phases[k].sigma > 0)
      bad("phases[" + std::to_string(k) + "].sigma", c.phases[k].sigma,
          ("the " + name + " model has no surface tension yet (sigma must be 0)").c_str());
  // Several rest densities: the mass density of a particle next to another phase is off by up to the
  // density ratio (docs/physics.md, the two-phase table), and the solver would drive that error to
  // zero with spurious interface pressures; the number density holds every phase at its own rho0.
  for (std::size_t k = 1; k < c.phases.size(); ++k)
    if (c.density == DensityFormulation::Mass && c.phases[k].rest_density != c.phases[0].rest_density) {
      std::ostringstream why;
      why << "the " << name
          << " model needs the number density (density = number) for phases of different rest "
             "densities (phases[0].rest_density = "
          << c.phases[0].rest_density << ", phases[" << k << "].rest_density = " << c.phases[k].rest_density
          << ")";
      bad("density", "mass", why.str().c_str());
    }
}

// The search subdivision and the moving walls.
template <int Dim, class Real>
void validate_motion(const SolverConfig<Dim, Real>& c) {
  if (c.search.subdivision < 1) bad("search.subdivision", c.search.subdivision, "must be >= 1");
  for (std::size_t k = 0; k < c.wall_motion.motions.size(); ++k) {
    const WallMotion& m = c.wall_motion.motions[k];
    const std::string key = "wall_motion[" + std::to_string(k) + "].";
    if (m.kind == MotionKind::Oscillate) {
      positive(key + "period", m.period);
      non_negative(key + "amplitude", m.amplitude);
    }
    if ((m.kind == MotionKind::Translate || m.kind == MotionKind::Rotate) && !(m.end >= m.start))
      bad(key + "end", m.end, "must not be before start");
    if (m.kind == MotionKind::Table &&
        !(m.table_begin < m.table_end && m.table_end <= c.wall_motion.rows.size()))
      bad(key + "table", m.table_end, "names no rows of the motion tables");
  }
  for (const std::int32_t m : c.wall_motion.of_particle)
    if (m < -1 || (m >= 0 && static_cast<std::size_t>(m) >= c.wall_motion.motions.size()))
      bad("wall_motion.of_particle", m, "is not -1 or a motion's index");
  if (c.wall_motion.any() && c.time.mode == TimeStepping::PerParticle)
    bad("time.mode", "per-particle", "moving walls need global time steps (fixed or courant)");
}

// Floating bodies.
template <int Dim, class Real>
void validate_bodies(const SolverConfig<Dim, Real>& c) {
  if (c.rigid_bodies.any()) {
    if (c.model != Model::Wcsph)
      bad("model", model_name(c.model),
          "floating bodies need the WCSPH model (solver.model = wcsph): their force is its wall term");
    if (c.time.mode == TimeStepping::PerParticle)
      bad("time.mode", "per-particle", "floating bodies need global time steps (fixed or courant)");
    if (c.wall_model == WallModel::Dynamic)
      bad("boundary.model", "dynamic",
          "floating bodies need akinci or adami walls (dynamic walls keep a wall-wall density of walls at "
          "rest)");
    positive("rigid_bodies.contact_distance", c.rigid_bodies.contact_distance);
    non_negative("rigid_bodies.contact_frequency", c.rigid_bodies.contact_frequency);
    non_negative("rigid_bodies.contact_damping", c.rigid_bodies.contact_damping);
    for (std::size_t k = 0; k < c.rigid_bodies.bodies.size(); ++k) {
      const RigidBody& b = c.rigid_bodies.bodies[k];
      const std::string key = "rigid_bodies[" + std::to_string(k) + "].";
      positive(key + "mass", b.mass);
      for (int a = 0; a < 3; ++a) positive(key + "inertia", b.inertia[4 * a]);
    }
    for (const std::int32_t b : c.rigid_bodies.of_particle)
      if (b < -1 || (b >= 0 && static_cast<std::size_t>(b) >= c.rigid_bodies.bodies.size()))
        bad("rigid_bodies.of_particle", b, "is not -1 or a body's index");
  }
}

// Emitters and sinks.
template <int Dim, class Real>
void validate_inflow(const SolverConfig<Dim, Real>& c) {
  if (const std::string err = inflow_config_error(c.inflow, Dim, c.phases.size()); !err.empty())
    throw InputError(err);
  if (c.inflow.any() && c.time.mode == TimeStepping::PerParticle)
    bad("time.mode", "per-particle", "emitters and sinks need global time steps (fixed or courant)");
}
}  // namespace

// Volume-map walls (boundary/bender2019.hpp): what this first version of them covers.
template <int Dim, class Real>
void validate_volume_map(const SolverConfig<Dim, Real>& c) {
  if (c.wall_model != WallModel::VolumeMap) return;
  const auto no = [&](const char* key, std::string_view value, const char* what) {
    bad(key, value, (std::string("volume-map walls (boundary.model = volume-map) ") + what).c_str());
  };
  if (!implicit_pressure(c.model))
    no("model", model_name(c.model), "need the DFSPH or IISPH model (solver.model = dfsph or iisph)");
  if (c.guard.moving())
    no("boundary.obstacles", "motion", "hold static solids only: a moving obstacle needs particle walls");
  if (c.rigid_bodies.any()) no("bodies", "floating", "do not move floating bodies yet");
  // A map built before (a config taken from a Simulation): its reach, and its grid's pitch where it has
  // one (a tank alone has no grid).
  if (!c.volume_map.empty() && !(c.volume_map.reach > 0))
    bad("volume_map.reach", c.volume_map.reach, "must be positive");
  if (!c.volume_map.nodes.empty() && !(c.volume_map.pitch > 0))
    bad("volume_map.pitch", c.volume_map.pitch, "must be positive where the map has a grid");
}

template <int Dim, class Real>
void SolverConfig<Dim, Real>::validate() const {
  validate_numbers(*this);
  validate_model_fit(*this);
  validate_collisions(*this);
  validate_density(*this);
  validate_implicit(*this);
  validate_motion(*this);
  validate_bodies(*this);
  validate_inflow(*this);
  validate_volume_map(*this);
}

std::string_view model_name(Model m) {
  return m == Model::PaperMultiphase ? "paper"
         : m == Model::Wcsph         ? "wcsph"
         : m == Model::Dfsph         ? "dfsph"
                                     : "iisph";
}
std::optional<Model> parse_model(std::string_view n) {
  if (n == "paper") return Model::PaperMultiphase;
  if (n == "wcsph") return Model::Wcsph;
  if (n == "dfsph") return Model::Dfsph;
  if (n == "iisph") return Model::Iisph;
  return std::nullopt;
}
std::string_view time_stepping_name(TimeStepping t) {
  switch (t) {
    case TimeStepping::Fixed:
      return "fixed";
    case TimeStepping::Courant:
      return "courant";
    case TimeStepping::PerParticle:
      return "per-particle";
  }
  return "?";
}
std::optional<TimeStepping> parse_time_stepping(std::string_view n) {
  for (auto t : {TimeStepping::Fixed, TimeStepping::Courant, TimeStepping::PerParticle})
    if (time_stepping_name(t) == n) return t;
  return std::nullopt;
}
std::string_view tension_model_name(TensionModel t) {
  return t == TensionModel::Paper ? "paper" : t == TensionModel::Csf ? "csf" : "akinci";
}
std::optional<TensionModel> parse_tension_model(std::string_view n) {
  if (n == "paper") return TensionModel::Paper;
  if (n == "csf") return TensionModel::Csf;
  if (n == "akinci") return TensionModel::Akinci;
  return std::nullopt;
}
std::string_view correction_name(StepChangeCorrection c) {
  return c == StepChangeCorrection::Exact ? "exact" : "printed";
}
std::optional<StepChangeCorrection> parse_correction(std::string_view n) {
  if (n == "exact") return StepChangeCorrection::Exact;
  if (n == "printed") return StepChangeCorrection::Printed;
  return std::nullopt;
}
std::string_view wall_model_name(WallModel w) {
  switch (w) {
    case WallModel::Akinci:
      return "akinci";
    case WallModel::Adami:
      return "adami";
    case WallModel::Dynamic:
      return "dynamic";
    case WallModel::VolumeMap:
      return "volume-map";
  }
  return "?";
}
std::optional<WallModel> parse_wall_model(std::string_view n) {
  if (n == "akinci") return WallModel::Akinci;
  if (n == "adami") return WallModel::Adami;
  if (n == "dynamic") return WallModel::Dynamic;
  if (n == "volume-map") return WallModel::VolumeMap;
  return std::nullopt;
}
std::string_view density_formulation_name(DensityFormulation d) {
  return d == DensityFormulation::Mass ? "mass" : "number";
}
std::optional<DensityFormulation> parse_density_formulation(std::string_view n) {
  if (n == "mass") return DensityFormulation::Mass;
  if (n == "number") return DensityFormulation::Number;
  return std::nullopt;
}

std::string_view density_diffusion_name(DensityDiffusion d) {
  switch (d) {
    case DensityDiffusion::None:
      return "none";
    case DensityDiffusion::Molteni:
      return "molteni";
    case DensityDiffusion::Fourtakas:
      return "fourtakas";
  }
  return "?";
}
std::optional<DensityDiffusion> parse_density_diffusion(std::string_view n) {
  for (auto d : {DensityDiffusion::None, DensityDiffusion::Molteni, DensityDiffusion::Fourtakas})
    if (density_diffusion_name(d) == n) return d;
  return std::nullopt;
}

template struct SolverConfig<2, float>;
template struct SolverConfig<2, double>;
template struct SolverConfig<3, float>;
template struct SolverConfig<3, double>;

}  // namespace cellsph
