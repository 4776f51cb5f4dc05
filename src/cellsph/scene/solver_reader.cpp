// /solver (docs/scenes.md, "solver"): model, kernels, equation of state, gravity, and the settings of
// DFSPH and IISPH.
#include "cellsph/scene/scene_readers.hpp"

#include <cmath>

#include "cellsph/physics/kernels.hpp"

namespace cellsph::scene_detail {

namespace {

// /solver/eos.
template <class Real>
void read_eos(JsonReader& sr, EquationOfState<Real>& eos) {
  if (!sr.has("eos")) return;
  auto er = sr.child("eos");
  eos.kind = *parse_eos(er.choice("kind", "tait", {"tait", "linear", "ratio", "seventh"}));
  eos.stiffness = static_cast<Real>(er.number("stiffness", double(eos.stiffness), 1e-12, 1e15));
  eos.gamma = static_cast<Real>(er.number("gamma", double(eos.gamma), 1e-3, 100));
  eos.clamp_negative = er.boolean("clamp_negative", eos.clamp_negative);
  er.finish();
}

// /solver/density_diffusion: {"kind": "none" | "molteni" | "fourtakas", "delta": 0.1}; needs the continuity
// density (read before it).
template <int Dim, class Real>
void read_density_diffusion(JsonReader& sr, SolverConfig<Dim, Real>& cfg) {
  if (!sr.has("density_diffusion")) return;
  auto dr = sr.child("density_diffusion");
  if (!dr.json().is_object()) dr.fail_here("expected an object, got " + json_value_text(dr.json()));
  const std::string kind = dr.choice("kind", "none", {"none", "molteni", "fourtakas"});
  cfg.density_diffusion.kind = *parse_density_diffusion(kind);
  cfg.density_diffusion.delta =
      static_cast<Real>(dr.number("delta", double(cfg.density_diffusion.delta), 0, 1));
  if (cfg.density_diffusion.kind != DensityDiffusion::None &&
      cfg.density_evolution != DensityEvolution::Continuity)
    dr.fail("kind",
            "\"" + kind + "\" diffuses an integrated density: needs /solver/density = \"continuity\"");
  dr.finish();
}

// /solver/artificial_viscosity: {"alpha": 0.01, "walls": false}; WCSPH only.
template <int Dim, class Real>
void read_artificial_viscosity(JsonReader& sr, SolverConfig<Dim, Real>& cfg) {
  if (!sr.has("artificial_viscosity")) return;
  auto ar = sr.child("artificial_viscosity");
  if (!ar.json().is_object()) ar.fail_here("expected an object, got " + json_value_text(ar.json()));
  cfg.artificial_viscosity.alpha = static_cast<Real>(ar.number("alpha", 0, 0, 10));
  cfg.artificial_viscosity.walls = ar.boolean("walls", false);
  if (cfg.artificial_viscosity.alpha > 0 && cfg.model != Model::Wcsph)
    ar.fail("alpha", "artificial viscosity is part of the WCSPH model (/solver/model = \"wcsph\")");
  ar.finish();
}

// The wall pressure of the DFSPH and IISPH pressure forces (/solver/dfsph or /solver/iisph wall_pressure).
DfsphWallPressure read_wall_pressure(JsonReader& r) {
  const std::string w = r.choice("wall_pressure", "zero", {"zero", "mirrored", "hydrostatic"});
  return w == "zero"       ? DfsphWallPressure::Zero
         : w == "mirrored" ? DfsphWallPressure::Mirrored
                           : DfsphWallPressure::Hydrostatic;
}

// /solver/iisph: IISPH's settings, kept in SolverConfig::dfsph (config.hpp).
template <class D>
void read_iisph(JsonReader& ir, D& d) {
  using Real = decltype(d.relaxation);
  d.max_density_error =
      static_cast<Real>(ir.number("max_density_error", double(d.max_density_error), 1e-9, 100));
  d.min_iterations = static_cast<int>(ir.integer("min_iterations", d.min_iterations, 0, 100000));
  d.max_iterations = static_cast<int>(ir.integer("max_iterations", d.max_iterations, 1, 100000));
  d.warm_start = ir.boolean("warm_start", d.warm_start);
  d.warm_start_scale = static_cast<Real>(ir.number("warm_start_scale", double(d.warm_start_scale), 1e-9, 1));
  d.relaxation = static_cast<Real>(ir.number("relaxation", double(d.relaxation), 1e-9, 1));
  d.wall_pressure = read_wall_pressure(ir);
  if (d.min_iterations > d.max_iterations)
    ir.fail("min_iterations", "value " + std::to_string(d.min_iterations) + " exceeds max_iterations " +
                                  std::to_string(d.max_iterations));
  ir.finish();
}

// /solver/dfsph: DFSPH's settings.
template <class D>
void read_dfsph(JsonReader& dr, D& d) {
  using Real = decltype(d.relaxation);
  d.max_density_error =
      static_cast<Real>(dr.number("max_density_error", double(d.max_density_error), 1e-9, 100));
  d.max_divergence_error =
      static_cast<Real>(dr.number("max_divergence_error", double(d.max_divergence_error), 1e-9, 100));
  d.min_iterations = static_cast<int>(dr.integer("min_iterations", d.min_iterations, 0, 100000));
  d.max_iterations = static_cast<int>(dr.integer("max_iterations", d.max_iterations, 1, 100000));
  d.warm_start = dr.boolean("warm_start", d.warm_start);
  d.warm_start_scale = static_cast<Real>(dr.number("warm_start_scale", double(d.warm_start_scale), 1e-9, 1));
  d.density_solver = dr.choice("density_solver", "jacobi", {"jacobi", "cg"}) == "cg"
                         ? DfsphDensitySolver::ConjugateGradient
                         : DfsphDensitySolver::Jacobi;
  d.wall_pressure = read_wall_pressure(dr);
  if (d.min_iterations > d.max_iterations)
    dr.fail("min_iterations", "value " + std::to_string(d.min_iterations) + " exceeds max_iterations " +
                                  std::to_string(d.max_iterations));
  dr.finish();
}

// /solver/model, with the defaults an implicit pressure solve changes.
template <int Dim, class Real>
void read_model(JsonReader& sr, SolverConfig<Dim, Real>& cfg) {
  cfg.model = *parse_model(sr.choice("model", "wcsph", {"paper", "wcsph", "dfsph", "iisph"}));
  if (implicit_pressure(cfg.model)) {
    cfg.time.courant = Real(0.4);  // on the particle diameter (models/dfsph.hpp)
    // A CFL step moves the fastest particle 0.4 d, three times the 0.45 of the default skin after which
    // the lists are rebuilt, so skinned lists seldom last a step; without the skin the rows, the stored
    // gradients and the row cut take less memory (peak heap 1.17x WCSPH's against 1.64x with the default
    // skin; docs/benchmarks.md, "DFSPH and IISPH against WCSPH and SPlisHSPlasH (3D)", memory).
    cfg.verlet_skin = Real(0);
  }
}

// /solver/support, the kernels and the density formulation.
template <int Dim, class Real>
void read_kernels(JsonReader& sr, double spacing, SolverConfig<Dim, Real>& cfg) {
  cfg.support = static_cast<Real>(sr.number("support", 2 * spacing, 1e-9, 1e9));
  if (cfg.support < static_cast<Real>(spacing))
    sr.fail("support", "value " + std::to_string(cfg.support) + " is smaller than the particle spacing " +
                           std::to_string(spacing) + ": particles would have no neighbours");
  std::vector<std::string> kernels;
  for (KernelKind k : {KernelKind::Poly6, KernelKind::Spiky, KernelKind::Viscosity, KernelKind::CubicSpline,
                       KernelKind::WendlandC2})
    kernels.emplace_back(kernel_name(k));
  cfg.density_kernel = *parse_kernel(sr.choice("density_kernel", "poly6", kernels));
  cfg.pressure_kernel = *parse_kernel(sr.choice("pressure_kernel", "spiky", kernels));
  const std::string density = sr.choice("density", "mass", {"mass", "number", "continuity"});
  if (density == "continuity") {
    if (cfg.model != Model::Wcsph)
      sr.fail("density", "\"continuity\" needs the WCSPH model (/solver/model = \"wcsph\")");
    cfg.density_evolution = DensityEvolution::Continuity;
  } else {
    cfg.density = *parse_density_formulation(density);
  }
}

}  // namespace

template <int Dim, class Real>
void read_solver(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg) {
  cfg.support = static_cast<Real>(2 * spacing);
  if (!r.has("solver")) {
    cfg.model = Model::Wcsph;
    return;
  }
  auto sr = r.child("solver");
  read_model(sr, cfg);
  cfg.backend = *parse_backend(sr.choice("backend", "cpu", {"cpu", "cuda", "host-device"}));
  read_kernels(sr, spacing, cfg);
  read_eos(sr, cfg.eos);
  read_density_diffusion(sr, cfg);
  read_artificial_viscosity(sr, cfg);
  if (sr.has("gravity")) {
    const auto g = sr.vector("gravity", Dim, {});
    for (double c : g)
      if (!(std::abs(c) <= 1e9))
        sr.fail("gravity", "component " + json_value_text(c) + " is beyond 1e9 m/s^2");
    cfg.gravity = to_vec<Dim, Real>(g);
  }
  cfg.tension_threshold = static_cast<Real>(sr.number("tension_threshold", 0, 0, 1e12));
  cfg.tension = *parse_tension_model(sr.choice("tension", "paper", {"paper", "csf", "akinci"}));
  cfg.restitution = static_cast<Real>(sr.number("restitution", double(cfg.restitution), 0, 1));
  cfg.friction = static_cast<Real>(sr.number("friction", double(cfg.friction), 0, 1));
  if (sr.has("iisph")) {
    auto ir = sr.child("iisph");
    if (cfg.model != Model::Iisph) ir.fail_here("is read only with /solver/model = \"iisph\"");
    read_iisph(ir, cfg.dfsph);
  }
  if (sr.has("dfsph")) {
    auto dr = sr.child("dfsph");
    if (cfg.model != Model::Dfsph) dr.fail_here("is read only with /solver/model = \"dfsph\"");
    read_dfsph(dr, cfg.dfsph);
  }
  sr.finish();
}

namespace {

const nlohmann::json* json_at(const nlohmann::json* o, const char* key) {
  return o && o->is_object() && o->contains(key) ? &(*o)[key] : nullptr;
}

// The settings of a scene that its model refuses, each with the edit that makes it fit.
struct Misfits {
  std::string what, sets;
  void add(const std::string& w, const std::string& set) {
    what += what.empty() ? "" : "; ";
    what += w;
    sets += sets.empty() ? "" : " ";
    sets += set;
  }
};

// The paper model's own settings (interface tension by CSF or Akinci 2013, per-particle steps).
void paper_only_misfits(const nlohmann::json& j, const std::string& name, Misfits& m) {
  const nlohmann::json* solver = json_at(&j, "solver");
  if (const nlohmann::json* t = json_at(solver, "tension"); t && t->is_string() && *t != "paper")
    m.add("/solver/tension is " + json_value_text(*t) + " (" + name + " has no CSF or Akinci tension)",
          "--set /solver/tension=paper");
  const nlohmann::json* time = json_at(&j, "time");
  if (const nlohmann::json* st = json_at(time, "stepping"); st && *st == "per-particle")
    m.add("/time/stepping is \"per-particle\" (the paper model's leap-frog only)",
          "--set /time/stepping=courant");
}

// WCSPH's own settings (artificial viscosity, the continuity density and its diffusion, floating bodies).
void wcsph_only_misfits(const nlohmann::json& j, Misfits& m) {
  if (const nlohmann::json* bodies = json_at(&j, "bodies"); bodies && !bodies->empty())
    m.add("/bodies is set (floating bodies need the WCSPH model, \"wcsph\": their force is its wall term)",
          "--set /bodies=null");
  const nlohmann::json* solver = json_at(&j, "solver");
  const nlohmann::json* av = json_at(solver, "artificial_viscosity");
  if (const nlohmann::json* alpha = json_at(av, "alpha");
      alpha && alpha->is_number() && alpha->get<double>() > 0)
    m.add("/solver/artificial_viscosity/alpha is " + json_value_text(*alpha) +
              " (artificial viscosity is part of the WCSPH model, \"wcsph\")",
          "--set /solver/artificial_viscosity/alpha=0");
  if (const nlohmann::json* d = json_at(solver, "density"); d && *d == "continuity")
    m.add("/solver/density is \"continuity\" (the continuity density is part of the WCSPH model, \"wcsph\")",
          "--set /solver/density=mass");
  const nlohmann::json* diffusion = json_at(solver, "density_diffusion");
  if (const nlohmann::json* kind = json_at(diffusion, "kind"); kind && *kind != "none")
    m.add(
        "/solver/density_diffusion is set (it diffuses the continuity density of the WCSPH model, \"wcsph\")",
        "--set /solver/density_diffusion=null");
}

// DFSPH's and IISPH's limits (Akinci or volume-map walls, no surface tension) and each one's settings
// section.
void implicit_misfits(const nlohmann::json& j, const std::string& name, Misfits& m) {
  const nlohmann::json* boundary = json_at(&j, "boundary");
  if (const nlohmann::json* wm = json_at(boundary, "model");
      wm && wm->is_string() && *wm != "akinci" && *wm != "volume-map")
    m.add("/boundary/model is " + json_value_text(*wm) + " (" + name +
              " holds Akinci 2012 boundary particles or volume maps)",
          "--set /boundary/model=akinci");
  if (const nlohmann::json* phases = json_at(&j, "phases"); phases && phases->is_array())
    for (std::size_t k = 0; k < phases->size(); ++k)
      if (const nlohmann::json* sigma = json_at(&(*phases)[k], "sigma");
          sigma && sigma->is_number() && sigma->get<double>() > 0)
        m.add("/phases/" + std::to_string(k) + "/sigma is " + json_value_text(*sigma) + " (" + name +
                  " has no surface tension yet)",
              "--set /phases/" + std::to_string(k) + "/sigma=0");
}

}  // namespace

// A scene switched to another model (`--set /solver/model=dfsph` on a WCSPH scene) may keep settings that
// the new model refuses: one message names them all, with the --set edits that make the scene fit,
// rather than one refusal per run (docs/physics.md, "Model 3").
void check_model_fits(const nlohmann::json& j, const std::string& source) {
  const nlohmann::json* solver = json_at(&j, "solver");
  const nlohmann::json* model = json_at(solver, "model");
  if (!model || !model->is_string()) return;
  const std::string m = *model;
  if (m != "paper" && m != "wcsph" && m != "dfsph" && m != "iisph") return;  // read_solver names it
  const std::string name = m == "paper"   ? "the paper model"
                           : m == "wcsph" ? "WCSPH"
                           : m == "dfsph" ? "DFSPH"
                                          : "IISPH";
  Misfits fits;
  if (m == "dfsph" || m == "iisph") implicit_misfits(j, name, fits);
  if (m != "wcsph") wcsph_only_misfits(j, fits);
  if (m != "paper") paper_only_misfits(j, name, fits);
  // The other implicit model's settings section (IISPH's are /solver/iisph, DFSPH's /solver/dfsph).
  if (m != "dfsph" && json_at(solver, "dfsph"))
    fits.add("/solver/dfsph is set (DFSPH's settings" +
                 std::string(m == "iisph" ? "; IISPH takes its own, /solver/iisph)" : ")"),
             "--set /solver/dfsph=null");
  if (m != "iisph" && json_at(solver, "iisph"))
    fits.add("/solver/iisph is set (IISPH's settings)", "--set /solver/iisph=null");
  if (fits.what.empty()) return;
  throw InputError(source + ": /solver/model = " + json_value_text(*model) +
                   " does not fit this scene's settings: " + fits.what + ". Add: " + fits.sets);
}

#define CELLSPH_SOLVER_INSTANTIATE(D, R) \
  template void read_solver<D, R>(JsonReader&, double, SolverConfig<D, R>&);
CELLSPH_SOLVER_INSTANTIATE(2, float)
CELLSPH_SOLVER_INSTANTIATE(2, double)
CELLSPH_SOLVER_INSTANTIATE(3, float)
CELLSPH_SOLVER_INSTANTIATE(3, double)
#undef CELLSPH_SOLVER_INSTANTIATE

}  // namespace cellsph::scene_detail
