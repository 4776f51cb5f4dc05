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
}  // namespace

template <int Dim, class Real>
void SolverConfig<Dim, Real>::validate() const {
  positive("support", support);
  positive("eos.stiffness", eos.stiffness);
  if (eos.kind == EosKind::Tait) positive("eos.gamma", eos.gamma);
  if (phases.empty()) bad("phases", "[]", "at least one phase is needed");
  for (std::size_t k = 0; k < phases.size(); ++k) {
    const std::string p = "phases[" + std::to_string(k) + "].";
    positive(p + "rest_density", phases[k].rest_density);
    non_negative(p + "mass", phases[k].mass);
    non_negative(p + "viscosity", phases[k].viscosity);
    if (!std::isfinite(phases[k].color)) bad(p + "color", phases[k].color, "must be finite");
    non_negative(p + "sigma", phases[k].sigma);
  }
  non_negative("tension_threshold", tension_threshold);
  non_negative("verlet_skin", verlet_skin);
  for (int a = 0; a < Dim; ++a)
    if (!std::isfinite(gravity[a])) bad("gravity[" + std::to_string(a) + "]", gravity[a], "must be finite");
  positive("time.dt", time.dt);
  positive("time.dt_max", time.dt_max);
  positive("time.courant", time.courant);
  positive("time.viscous", time.viscous);
  positive("time.force", time.force);
  if (time.max_level < 0 || time.max_level > 40) bad("time.max_level", time.max_level, "must be in [0, 40]");
  if (tension != TensionModel::Paper && model != Model::PaperMultiphase)
    bad("tension", tension_model_name(tension),
        "the WCSPH model has the write-up's Mueller tension; csf and akinci need the paper model (model = "
        "paper)");
  if (time.mode == TimeStepping::PerParticle && model != Model::PaperMultiphase)
    bad("time.mode", "per-particle", "per-particle steps need the paper model's leap-frog (model = paper)");
  // Wall states are computed from all fluid densities of a step; a per-particle sub-step has only some.
  if (wall_model != WallModel::Akinci && time.mode == TimeStepping::PerParticle)
    bad("boundary.model", wall_model_name(wall_model),
        "needs global steps (time.mode fixed or courant), not per-particle");
  if (box.enabled) {
    for (int a = 0; a < Dim; ++a)
      if (!(box.hi[a] - 2 * box.radius > box.lo[a]))
        bad("box.hi[" + std::to_string(a) + "]", box.hi[a], "must exceed box.lo + 2 radius");
    non_negative("box.radius", box.radius);
    if (!(box.damping <= 0 && box.damping >= -1)) bad("box.damping", box.damping, "must be in [-1, 0]");
  }
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const Real n2 = norm2(planes[k].normal);
    if (!(std::abs(n2 - 1) < Real(1e-3)))
      bad("planes[" + std::to_string(k) + "].normal", std::sqrt(n2), "must have unit length");
  }
  if (!(restitution >= 0 && restitution <= 1)) bad("restitution", restitution, "must be in [0, 1]");
  if (!(friction >= 0 && friction <= 1)) bad("friction", friction, "must be in [0, 1]");
  if (density_evolution == DensityEvolution::Continuity && model != Model::Wcsph)
    bad("density", "continuity", "the continuity equation needs the WCSPH model (model = wcsph)");
  if (density_diffusion.kind != DensityDiffusion::None) {
    if (density_evolution != DensityEvolution::Continuity)
      bad("density_diffusion.kind", density_diffusion_name(density_diffusion.kind),
          "diffuses an integrated density: needs density = continuity");
    if (!(std::isfinite(density_diffusion.delta) && density_diffusion.delta >= 0 &&
          density_diffusion.delta <= 1))
      bad("density_diffusion.delta", density_diffusion.delta, "must be in [0, 1]");
  }
  if (!(std::isfinite(artificial_viscosity.alpha) && artificial_viscosity.alpha >= 0 &&
        artificial_viscosity.alpha <= 10))
    bad("artificial_viscosity.alpha", artificial_viscosity.alpha, "must be in [0, 10]");
  if (artificial_viscosity.alpha > 0 && model != Model::Wcsph)
    bad("artificial_viscosity.alpha", artificial_viscosity.alpha,
        "artificial viscosity is part of the WCSPH model (model = wcsph)");
  if (implicit_pressure(model)) {
    // IISPH's settings are SolverConfig::dfsph too; its messages name them as the scene does (iisph.*).
    const std::string sec = model == Model::Iisph ? "iisph." : "dfsph.";
    const std::string name = model == Model::Iisph ? "IISPH" : "DFSPH";
    positive(sec + "max_density_error", dfsph.max_density_error);
    if (model == Model::Dfsph) positive("dfsph.max_divergence_error", dfsph.max_divergence_error);
    if (dfsph.min_iterations < 0) bad(sec + "min_iterations", dfsph.min_iterations, "must be >= 0");
    if (dfsph.max_iterations < 1) bad(sec + "max_iterations", dfsph.max_iterations, "must be >= 1");
    if (dfsph.min_iterations > dfsph.max_iterations)
      bad(sec + "min_iterations", dfsph.min_iterations,
          ("must not exceed " + sec + "max_iterations = " + std::to_string(dfsph.max_iterations)).c_str());
    if (!(dfsph.warm_start_scale > 0 && dfsph.warm_start_scale <= 1))
      bad(sec + "warm_start_scale", dfsph.warm_start_scale, "must be in (0, 1]");
    if (model == Model::Iisph && !(dfsph.relaxation > 0 && dfsph.relaxation <= 1))
      bad("iisph.relaxation", dfsph.relaxation, "must be in (0, 1]");
    if (model == Model::Iisph && dfsph.density_solver != DfsphDensitySolver::Jacobi)
      bad("dfsph.density_solver", "cg", "IISPH's solve is its relaxed Jacobi iteration");
    // Several phases: the number density's system is not symmetric in k (its pair force weighs m_i^2 k_i
    // and m_j^2 k_j), which CG needs.
    if (dfsph.density_solver == DfsphDensitySolver::ConjugateGradient &&
        density == DensityFormulation::Number)
      bad("dfsph.density_solver", "cg",
          "the conjugate-gradient solve needs the mass density of one phase; several phases (density = "
          "number) take \"jacobi\"");
    // Adami and dynamic walls take their pressure from the fluid's (extrapolated) or from an equation of
    // state; neither is an unknown of the DFSPH solves, so the factor alpha_i would not describe what a
    // sweep changes (docs/physics.md, "DFSPH").
    if (wall_model != WallModel::Akinci)
      bad("boundary.model", wall_model_name(wall_model),
          ("the " + name + " model supports Akinci 2012 boundary particles only (boundary.model = akinci)")
              .c_str());
    for (std::size_t k = 0; k < phases.size(); ++k)
      if (phases[k].sigma > 0)
        bad("phases[" + std::to_string(k) + "].sigma", phases[k].sigma,
            ("the " + name + " model has no surface tension yet (sigma must be 0)").c_str());
    // Several rest densities: the mass density of a particle next to another phase is off by up to the
    // density ratio (docs/physics.md, the two-phase table), and the solver would drive that error to
    // zero with spurious interface pressures; the number density holds every phase at its own rho0.
    for (std::size_t k = 1; k < phases.size(); ++k)
      if (density == DensityFormulation::Mass && phases[k].rest_density != phases[0].rest_density) {
        std::ostringstream why;
        why << "the " << name
            << " model needs the number density (density = number) for phases of different rest "
               "densities (phases[0].rest_density = "
            << phases[0].rest_density << ", phases[" << k << "].rest_density = " << phases[k].rest_density
            << ")";
        bad("density", "mass", why.str().c_str());
      }
  }
  if (search.subdivision < 1) bad("search.subdivision", search.subdivision, "must be >= 1");
  for (std::size_t k = 0; k < wall_motion.motions.size(); ++k) {
    const WallMotion& m = wall_motion.motions[k];
    const std::string key = "wall_motion[" + std::to_string(k) + "].";
    if (m.kind == MotionKind::Oscillate) {
      positive(key + "period", m.period);
      non_negative(key + "amplitude", m.amplitude);
    }
    if ((m.kind == MotionKind::Translate || m.kind == MotionKind::Rotate) && !(m.end >= m.start))
      bad(key + "end", m.end, "must not be before start");
    if (m.kind == MotionKind::Table &&
        !(m.table_begin < m.table_end && m.table_end <= wall_motion.rows.size()))
      bad(key + "table", m.table_end, "names no rows of the motion tables");
  }
  for (const std::int32_t m : wall_motion.of_particle)
    if (m < -1 || (m >= 0 && static_cast<std::size_t>(m) >= wall_motion.motions.size()))
      bad("wall_motion.of_particle", m, "is not -1 or a motion's index");
  if (wall_motion.any() && time.mode == TimeStepping::PerParticle)
    bad("time.mode", "per-particle", "moving walls need global time steps (fixed or courant)");
  if (rigid_bodies.any()) {
    if (model != Model::Wcsph)
      bad("model", model_name(model),
          "floating bodies need the WCSPH model (solver.model = wcsph): their force is its wall term");
    if (time.mode == TimeStepping::PerParticle)
      bad("time.mode", "per-particle", "floating bodies need global time steps (fixed or courant)");
    if (wall_model == WallModel::Dynamic)
      bad("boundary.model", "dynamic",
          "floating bodies need akinci or adami walls (dynamic walls keep a wall-wall density of walls at "
          "rest)");
    positive("rigid_bodies.contact_distance", rigid_bodies.contact_distance);
    non_negative("rigid_bodies.contact_frequency", rigid_bodies.contact_frequency);
    non_negative("rigid_bodies.contact_damping", rigid_bodies.contact_damping);
    for (std::size_t k = 0; k < rigid_bodies.bodies.size(); ++k) {
      const RigidBody& b = rigid_bodies.bodies[k];
      const std::string key = "rigid_bodies[" + std::to_string(k) + "].";
      positive(key + "mass", b.mass);
      for (int a = 0; a < 3; ++a) positive(key + "inertia", b.inertia[4 * a]);
    }
    for (const std::int32_t b : rigid_bodies.of_particle)
      if (b < -1 || (b >= 0 && static_cast<std::size_t>(b) >= rigid_bodies.bodies.size()))
        bad("rigid_bodies.of_particle", b, "is not -1 or a body's index");
  }
  if (const std::string err = inflow_config_error(inflow, Dim, phases.size()); !err.empty())
    throw InputError(err);
  if (inflow.any() && time.mode == TimeStepping::PerParticle)
    bad("time.mode", "per-particle", "emitters and sinks need global time steps (fixed or courant)");
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
  }
  return "?";
}
std::optional<WallModel> parse_wall_model(std::string_view n) {
  if (n == "akinci") return WallModel::Akinci;
  if (n == "adami") return WallModel::Adami;
  if (n == "dynamic") return WallModel::Dynamic;
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
