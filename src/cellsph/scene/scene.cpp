#include "cellsph/scene/scene.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>

#include "cellsph/core/parallel.hpp"
#include "cellsph/geometry/mesh.hpp"
#include "cellsph/geometry/shape.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/scene/builtin_scenes.hpp"
#include "cellsph/scene/inflow_reader.hpp"
#include "cellsph/scene/json_reader.hpp"
#include "cellsph/solver/initial.hpp"

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

namespace {

// Offset of the first byte of `s` that is not part of well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF), or npos. A JSON string must be UTF-8: nlohmann's parser checks
// the scene file, this the --set values that are taken as strings verbatim.
std::size_t invalid_utf8_at(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
    if (c < 0x80) {
      ++i;
      continue;
    }
    if (c >= 0xC2 && c <= 0xDF) {
      n = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 2;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 3;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return i;
    }
    if (s.size() - i <= n) return i;
    for (std::size_t k = 1; k <= n; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF)) return i;
    }
    i += n + 1;
  }
  return std::string_view::npos;
}

// Refuses an edit whose pointer would grow an array by more than one element: nlohmann's operator[]
// fills every index up to the one named, so /phases/100000000/viscosity would make 10^8 values (found by
// fuzz/scene_fuzz.cpp, 44 million from a 30-byte input). One past the end appends, like "-".
void check_array_indices(const nlohmann::json& j, const std::string& edit, const std::string& pointer) {
  std::vector<std::string> tokens;
  for (nlohmann::json::json_pointer p(pointer); !p.empty(); p.pop_back())
    tokens.insert(tokens.begin(), p.back());
  const nlohmann::json* cur = &j;  // nullptr once the path leaves what exists
  std::string path;
  for (const auto& t : tokens) {
    const bool digits =
        !t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    const bool array = cur ? cur->is_array() : false;
    if (digits && (array || !cur || cur->is_null())) {
      const std::size_t size = array ? cur->size() : 0;
      if (t.size() > 9 || std::stoul(t) > size)
        throw InputError("--set '" + edit + "': index " + t + " is beyond the end of " +
                         (path.empty() ? "/" : path) + " (" + std::to_string(size) +
                         " elements: the next is " + std::to_string(size) + " or -)");
      cur = std::stoul(t) < size ? &(*cur)[std::stoul(t)] : nullptr;
    } else {
      cur = cur && cur->is_object() && cur->contains(t) ? &(*cur)[t] : nullptr;
    }
    path += "/" + t;
  }
}

}  // namespace

void apply_scene_edits(nlohmann::json& j, const std::vector<std::string>& edits, std::string& source) {
  if (edits.empty()) return;
  std::string list;
  for (const auto& e : edits) {
    if (const auto bad = invalid_utf8_at(e); bad != std::string_view::npos) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(e[bad])));
      throw InputError("--set: edit " + json_value_text(nlohmann::json(e.substr(0, bad))) +
                       "... is not valid UTF-8 (byte " + hex + " at offset " + std::to_string(bad) + ")");
    }
    const auto eq = e.find('=');
    if (eq == std::string::npos || eq == 1 || e[0] != '/')
      throw InputError("--set '" + e + "': expected /json/pointer=value, e.g. /phases/0/viscosity=1");
    const std::string text = e.substr(eq + 1);
    if (text.empty()) throw InputError("--set '" + e + "': no value after '='");
    nlohmann::json value = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = text;
    try {
      const nlohmann::json::json_pointer ptr(e.substr(0, eq));
      if (value.is_null()) {  // null removes the key (no scene key takes null)
        if (!j.contains(ptr))
          throw InputError("--set '" + e + "': " + ptr.to_string() + " is not in the scene");
        nlohmann::json& parent = j[ptr.parent_pointer()];
        if (parent.is_array())
          parent.erase(static_cast<std::size_t>(std::stoul(ptr.back())));
        else
          parent.erase(ptr.back());
      } else {
        check_array_indices(j, e, e.substr(0, eq));
        j[ptr] = std::move(value);
      }
    } catch (const nlohmann::json::exception& ex) {
      throw InputError("--set '" + e + "': " + ex.what());
    }
    list += (list.empty() ? "" : " ") + e;
  }
  source += " (edited: " + list + ")";
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

namespace {

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

// Length of the ray x + t d (t >= 0) inside the box (slab method).
template <int Dim>
double ray_length_in(const Aabb<Dim>& b, const std::array<double, Dim>& x, const std::array<double, Dim>& d) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < Dim; ++a) {
    if (d[a] == 0) {
      if (x[a] < b.lo[a] || x[a] > b.hi[a]) return 0;
      continue;
    }
    const double u = (b.lo[a] - x[a]) / d[a], v = (b.hi[a] - x[a]) / d[a];
    t0 = std::max(t0, std::min(u, v));
    t1 = std::min(t1, std::max(u, v));
  }
  return std::max(0.0, t1 - t0);
}

// sum_k W(|k| spacing) over the whole lattice (k integer, self included): the summation density of a
// lattice site inside the fluid is m times this, which differs from 1 / spacing^Dim by a fraction of a
// percent (enough for a pressure of the order of rho0 g H at the dam breaks' sound speed).
template <int Dim, class Real>
double lattice_kernel_sum(const SolverConfig<Dim, Real>& cfg, double spacing) {
  const int K = static_cast<int>(std::ceil(double(cfg.support) / spacing));
  double sum = 0;
  with_kernel<Dim, Real>(cfg.density_kernel, cfg.support, [&](const auto w) {
    std::array<int, Dim> k;
    k.fill(-K);
    while (true) {
      double r2 = 0;
      for (int a = 0; a < Dim; ++a) r2 += double(k[a]) * double(k[a]) * spacing * spacing;
      sum += double(w.W2(static_cast<Real>(r2)));
      int a = 0;
      while (a < Dim && ++k[a] > K) k[a++] = -K;
      if (a == Dim) break;
    }
  });
  return sum;
}

// Fluid at rest under gravity: every fluid particle gets the pressure of the fluid above it,
// p = |g| sum_b rho0_b L_b (L_b: the length of the ray from the particle against gravity inside fluid
// block b), and the mass at which the summation density of its lattice site is the state equation's
// density for p: m = rho(p) / lattice_kernel_sum. A column then starts in equilibrium instead of
// falling onto itself while its pressure builds (and without the uniform pressure that the lattice
// sum's bias gives with m = rho0 spacing^Dim). Blocks do not overlap; walls and obstacles above carry no
// weight. A phase whose mass the scene sets keeps it.
// DFSPH has no equation of state (its fluid is incompressible): there every mass is rho0 over the lattice
// sum, so that the summation density of each lattice site is rho0 exactly, and the solver finds the
// pressure itself. (The WCSPH masses compressed by whatever eos the scene holds made a DFSPH column
// explode in its first steps: lobovsky-2014 switched to DFSPH lost a particle at t = 1 ms. Handing the
// first solve rho0 g depth as a warm start was tried: 6 sweeps instead of 2, so it is not done.)
template <int Dim, class Real>
void start_hydrostatic(Particles<Dim, Real>& p, const SolverConfig<Dim, Real>& cfg, double spacing,
                       const std::vector<bool>& mass_given, const std::vector<Aabb<Dim>>& blocks,
                       const std::vector<std::int32_t>& block_phase, const std::vector<double>& extra) {
  double g2 = 0;
  for (int a = 0; a < Dim; ++a) g2 += double(cfg.gravity[a]) * double(cfg.gravity[a]);
  const double g = std::sqrt(g2);
  const double volume = 1 / lattice_kernel_sum(cfg, spacing);
  std::array<double, Dim> up{};
  for (int a = 0; a < Dim; ++a) up[static_cast<std::size_t>(a)] = g > 0 ? -double(cfg.gravity[a]) / g : 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != static_cast<std::uint8_t>(ParticleKind::Fluid)) continue;
    std::array<double, Dim> x{};
    for (int a = 0; a < Dim; ++a) x[static_cast<std::size_t>(a)] = double(p.x[i][a]);
    double pressure = extra[i];
    if (g > 0)
      for (std::size_t b = 0; b < blocks.size(); ++b)
        pressure += g * double(cfg.phases[static_cast<std::size_t>(block_phase[b])].rest_density) *
                    ray_length_in<Dim>(blocks[b], x, up);
    const auto ph = static_cast<std::size_t>(p.phase[i]);
    const Real rho0 = cfg.phases[ph].rest_density;
    const bool incompressible = implicit_pressure(cfg.model);
    const double rho =
        incompressible ? double(rho0) : double(cfg.eos.density(static_cast<Real>(pressure), rho0));
    p.m[i] = mass_given[ph] ? static_cast<Real>(double(cfg.phases[ph].mass) * rho / double(rho0))
                            : static_cast<Real>(rho * volume);
    // The continuity density starts from it (summation density recomputes it from the masses).
    if (p.rho.size() == p.size()) p.rho[i] = static_cast<Real>(rho);
  }
}

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

// About what one particle costs in a run: 256 bytes of fields and search structures, and 8 bytes for
// each pair within the search radius h (1 + skin) (a 4-byte entry in the search's lists and in the
// lists cut to h). For the 3D dam break (2.3 spacings, 51 pairs) that is 664 bytes; at 1.5e6
// particles (1e6 fluid) it peaked at 0.96 GB resident, 640 bytes a particle.
double pairs_per_particle(int dim, double search_radius_in_spacings) {
  const double r = search_radius_in_spacings;
  return dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
}
double bytes_per_particle(double pairs) {
  return 256 + 8 * pairs;
}

// Counts the particles a scene asks for before any is made, so that a spacing too fine for this
// machine stops with the key and the count instead of hours of allocation or std::bad_alloc. The
// limit is what the machine's memory holds at bytes_per_particle, and never above 2^31 (indices).
class ParticleBudget {
 public:
  // `radius`: the search radius h (1 + skin) in spacings, which sets the pairs each particle keeps.
  // `memory`: the bytes the particles may take (SceneLimits), 0 for this machine's memory.
  ParticleBudget(int dim, double spacing, double radius, double memory) : spacing_(spacing) {
    limit_ = double(std::size_t{1} << 31);
    why_ = "2^31, the most particles a run can index";
    const double pairs = pairs_per_particle(dim, radius), bytes = bytes_per_particle(pairs);
    std::string whose = "this machine's";
    if (memory > 0) {
      whose = "the allowed";
    } else {
      const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
      memory = pages > 0 && page > 0 ? double(pages) * double(page) : 0;
    }
    if (memory > 0 && memory / bytes < limit_) {
      limit_ = memory / bytes;
      why_ = "what " + whose + " " + number(memory / double(1L << 30)) + " GiB of memory hold at about " +
             number(bytes) + " bytes a particle, which has " + number(pairs) + " neighbours within " +
             number(radius) + " spacings";
    }
    // A support of many spacings makes every particle costly: name that way out too.
    fix_ = radius > 8 ? "use a larger /spacing or a smaller /solver/support" : "use a larger /spacing";
  }

  // The lattice sites a shape's sampling walks (its bounding box): at most 64 per particle of the limit, so
  // that a thin shape in a huge box cannot take hours to sample.
  void take_sites(double sites, const JsonReader& r, const std::string& key, const std::string& what) const {
    if (sites > 64 * limit_)
      r.fail(key, "the bounding box of " + what + " spans " + number(sites) + " lattice sites at spacing " +
                      number(spacing_) + ", more than 64 times the particle limit " + number(limit_) + ": " +
                      fix_);
  }

  // A lattice site's index along `axis` must fit its integer: fails at `key` if the object reaches `far`
  // metres from the origin, more than 2^50 spacings.
  void check_reach(double far, int axis, const JsonReader& r, const std::string& key,
                   const std::string& what) const {
    if (!(far / spacing_ < geometry::kMaxLatticeIndex))
      r.fail(key, what + " reaches " + number(far) + " m from the origin along axis " + std::to_string(axis) +
                      ", more than 2^50 spacings of " + number(spacing_) + " m: move it closer or use a " +
                      "coarser spacing");
  }

  // Adds `count` particles made by the object at `key` of `r`; fails there if the total is too many.
  void take(double count, const JsonReader& r, const std::string& key, const std::string& what) {
    planned_ += count;
    if (planned_ > limit_)
      r.fail(key, "with " + what + " at spacing " + number(spacing_) + " m the scene has " +
                      number(planned_) + " particles, more than " + number(limit_) + " (" + why_ +
                      "): " + fix_);
  }

 private:
  static std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
  }
  double spacing_, limit_ = 0, planned_ = 0;
  std::string why_, fix_;
};

// Number of lattice cells of `spacing` along each axis of a block.
template <int Dim>
std::array<long, 3> cells_of(const Aabb<Dim>& b, double spacing) {
  std::array<long, 3> n{1, 1, 1};
  for (std::size_t a = 0; a < Dim; ++a) n[a] = std::lround((b.hi[a] - b.lo[a]) / spacing);
  return n;
}

// Each function below reads one section of docs/scenes.md from the top-level reader `r`: it owns the
// section's keys, their defaults and their errors. load_scene calls them in the order in which their
// errors are reported (a section may use what the earlier ones set: the time section checks the model,
// the walls the first phase's density and gravity).

// --- phases (/phases) ---------------------------------------------------------------------------
// What the later sections need from the phases.
struct PhaseTable {
  std::vector<std::string> names;
  std::vector<bool> mass_given;  // phases[k].mass set by the scene

  // The "phase" key of a fluid block: an index or a name of a phase; 0 when absent.
  std::int32_t read_reference(JsonReader& e) const {
    if (!e.has("phase")) return 0;
    const auto& v = e.json()["phase"];
    if (v.is_string()) {
      const std::string name = e.string("phase", "");
      for (std::size_t k = 0; k < names.size(); ++k)
        if (names[k] == name) return static_cast<std::int32_t>(k);
      e.fail("phase", "no phase named \"" + name + "\"");
    }
    return static_cast<std::int32_t>(e.integer("phase", 0, 0, static_cast<long>(names.size()) - 1));
  }
};

template <int Dim, class Real>
PhaseTable read_phases(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg) {
  PhaseTable t;
  if (!r.has("phases")) {
    cfg.phases[0].mass = cfg.phases[0].rest_density * static_cast<Real>(std::pow(spacing, Dim));
    t.names.push_back(cfg.phases[0].name);
    t.mass_given.push_back(false);
    return t;
  }
  cfg.phases.clear();
  auto pr = r.child("phases");
  const std::size_t np = pr.array_size();
  if (np == 0) pr.fail_here("at least one phase is needed");
  for (std::size_t k = 0; k < np; ++k) {
    auto e = pr.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    Phase<Real> ph;
    ph.name = e.string("name", "phase" + std::to_string(k));
    ph.rest_density = static_cast<Real>(e.number("rest_density", 1000, 1e-6, 1e9));
    ph.mass = static_cast<Real>(e.number("mass", 0, 0, 1e12));
    ph.viscosity = static_cast<Real>(e.number("viscosity", 0, 0, 1e9));
    ph.color = static_cast<Real>(e.number("color", 1, -1e9, 1e9));
    ph.sigma = static_cast<Real>(e.number("sigma", 0, 0, 1e9));
    e.finish();
    t.mass_given.push_back(ph.mass != 0);
    if (ph.mass == 0) ph.mass = ph.rest_density * static_cast<Real>(std::pow(spacing, Dim));
    t.names.push_back(ph.name);
    cfg.phases.push_back(ph);
  }
  return t;
}

// --- solver (/solver, with /solver/eos) --------------------------------------------------------------
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
inline DfsphWallPressure read_wall_pressure(JsonReader& r) {
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

template <int Dim, class Real>
void read_solver(JsonReader& r, double spacing, SolverConfig<Dim, Real>& cfg) {
  cfg.support = static_cast<Real>(2 * spacing);
  if (!r.has("solver")) {
    cfg.model = Model::Wcsph;
    return;
  }
  auto sr = r.child("solver");
  cfg.model = *parse_model(sr.choice("model", "wcsph", {"paper", "wcsph", "dfsph", "iisph"}));
  if (implicit_pressure(cfg.model)) {
    cfg.time.courant = Real(0.4);  // on the particle diameter (models/dfsph.hpp)
    // A CFL step moves the fastest particle 0.4 d, three times the 0.45 of the default skin after which
    // the lists are rebuilt, so skinned lists seldom last a step; without the skin the rows, the stored
    // gradients and the row cut take less memory (peak heap 1.17x WCSPH's against 1.64x with the default
    // skin; docs/benchmarks.md, "DFSPH and IISPH against WCSPH and SPlisHSPlasH (3D)", memory).
    cfg.verlet_skin = Real(0);
  }
  cfg.backend = *parse_backend(sr.choice("backend", "cpu", {"cpu", "cuda", "host-device"}));
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
    auto& d = cfg.dfsph;
    d.max_density_error =
        static_cast<Real>(dr.number("max_density_error", double(d.max_density_error), 1e-9, 100));
    d.max_divergence_error =
        static_cast<Real>(dr.number("max_divergence_error", double(d.max_divergence_error), 1e-9, 100));
    d.min_iterations = static_cast<int>(dr.integer("min_iterations", d.min_iterations, 0, 100000));
    d.max_iterations = static_cast<int>(dr.integer("max_iterations", d.max_iterations, 1, 100000));
    d.warm_start = dr.boolean("warm_start", d.warm_start);
    d.warm_start_scale =
        static_cast<Real>(dr.number("warm_start_scale", double(d.warm_start_scale), 1e-9, 1));
    d.density_solver = dr.choice("density_solver", "jacobi", {"jacobi", "cg"}) == "cg"
                           ? DfsphDensitySolver::ConjugateGradient
                           : DfsphDensitySolver::Jacobi;
    d.wall_pressure = read_wall_pressure(dr);
    if (d.min_iterations > d.max_iterations)
      dr.fail("min_iterations", "value " + std::to_string(d.min_iterations) + " exceeds max_iterations " +
                                    std::to_string(d.max_iterations));
    dr.finish();
  }
  sr.finish();
}

// --- time (/time; after the solver: per-particle steps need the paper model) -------------------------
template <int Dim, class Real>
void read_time(JsonReader& r, SolverConfig<Dim, Real>& cfg, OutputSettings& out) {
  if (!r.has("time")) {
    cfg.time.mode = TimeStepping::Courant;
    return;
  }
  auto tr = r.child("time");
  out.end_time = tr.number("end", out.end_time, 1e-12, 1e9);
  cfg.time.mode =
      *parse_time_stepping(tr.choice("stepping", "courant", {"fixed", "courant", "per-particle"}));
  if (cfg.time.mode == TimeStepping::PerParticle && cfg.model != Model::PaperMultiphase)
    tr.fail("stepping", "\"per-particle\" needs the paper model (/solver/model = \"paper\")");
  cfg.time.max_level = static_cast<int>(tr.integer("max_level", cfg.time.max_level, 0, 30));
  cfg.time.correction = *parse_correction(tr.choice("correction", "exact", {"exact", "printed"}));
  cfg.time.dt = static_cast<Real>(tr.number("dt", double(cfg.time.dt), 1e-12, 10));
  cfg.time.dt_max = static_cast<Real>(tr.number("dt_max", double(cfg.time.dt_max), 1e-12, 10));
  cfg.time.courant = static_cast<Real>(tr.number("courant", double(cfg.time.courant), 1e-6, 2));
  cfg.time.viscous = static_cast<Real>(tr.number("viscous", double(cfg.time.viscous), 1e-6, 10));
  cfg.time.force = static_cast<Real>(tr.number("force", double(cfg.time.force), 1e-6, 10));
  tr.finish();
}

// --- neighbour search (/neighbors) --------------------------------------------------------------
template <int Dim, class Real>
void read_neighbors(JsonReader& r, SolverConfig<Dim, Real>& cfg) {
  if (!r.has("neighbors")) return;
  auto nr = r.child("neighbors");
  std::vector<std::string> methods;
  for (Method m : kAllMethods) methods.emplace_back(method_name(m));
  cfg.search.method = *parse_method(nr.choice("method", "cell-index", methods));
  cfg.search.subdivision = static_cast<int>(nr.integer("subdivision", 1, 1, 16));
  cfg.search.hash_table_size = static_cast<std::size_t>(nr.integer("hash_table_size", 0, 0, 4294967294L));
  cfg.verlet_skin = static_cast<Real>(nr.number("skin", double(cfg.verlet_skin), 0, 1));
  cfg.reorder_every = static_cast<std::uint32_t>(
      nr.integer("reorder_every", static_cast<long>(cfg.reorder_every), 0, 1000000));
  nr.finish();
}

// --- boundary (/boundary) and domain (/domain) --------------------------------------------------
// The regions the fluid blocks are checked against.
template <int Dim>
struct Regions {
  std::vector<Aabb<Dim>> solids;       // regions fluid must not overlap
  std::optional<Aabb<Dim>> container;  // region fluid must lie in
  // Shaped obstacles and containers (boundary.obstacles with "mesh", "sphere" or "cylinder"): fluid
  // particles keep half a spacing outside every obstacle and inside some container.
  std::vector<geometry::Shape> solid_shapes, container_shapes;
  std::vector<std::string> shape_keys;  // key paths of all shapes, for the domain check
  std::vector<geometry::Shape> all_shapes;
  std::vector<double> shape_margins;  // how far each shape's particles reach beyond it
};

// Where a scene's mesh files are: beside the scene file, or compiled in for a built-in scene.
struct MeshFiles {
  bool builtin = false;
  std::filesystem::path dir;
};

MeshFiles mesh_files_of(const std::string& source) {
  std::string s = source;
  if (const auto ed = s.find(" (edited: "); ed != std::string::npos) s.resize(ed);
  if (s.rfind("built-in scene ", 0) == 0) return {true, {}};
  return {false, std::filesystem::path(s).parent_path()};
}

// The shape of an obstacle or fluid volume at `e`: "mesh", "sphere" or "cylinder" (docs/scenes.md,
// "Shapes"); nothing when it is a box ("min", "max").
template <int Dim>
std::optional<geometry::Shape> read_shape(JsonReader& e, double spacing, const MeshFiles& files) {
  int given = 0;
  for (const char* k : {"min", "mesh", "sphere", "cylinder"}) given += e.has(k) ? 1 : 0;
  if (given > 1) e.fail_here("give one shape: \"min\"/\"max\" (a box), \"mesh\", \"sphere\" or \"cylinder\"");
  if (e.has("sphere")) {
    auto sr = e.child("sphere");
    const auto c = sr.required_vector("center", Dim);
    geometry::Sphere sp;
    for (std::size_t a = 0; a < Dim; ++a) sp.center[a] = c[a];
    sp.radius = sr.required_number("radius", 0, 1e9);
    if (!(sp.radius > 0)) sr.fail("radius", "must be > 0");
    sr.finish();
    return geometry::Shape::sphere(sp, Dim);
  }
  if (e.has("cylinder")) {
    auto cr = e.child("cylinder");
    const auto b = cr.required_vector("base", Dim);
    const auto ax = cr.required_vector("axis", Dim);
    geometry::Cylinder cy;
    double len = 0;
    for (std::size_t a = 0; a < Dim; ++a) len += ax[a] * ax[a];
    len = std::sqrt(len);
    if (!(len > 0) || !std::isfinite(len)) cr.fail("axis", "must be a non-zero vector");
    for (std::size_t a = 0; a < Dim; ++a) {
      cy.base[a] = b[a];
      cy.axis[a] = ax[a] / len;
    }
    if (Dim == 2) cy.axis[2] = 0;
    cy.radius = cr.required_number("radius", 0, 1e9);
    if (!(cy.radius > 0)) cr.fail("radius", "must be > 0");
    cy.height = cr.required_number("height", 0, 1e9);
    if (!(cy.height > 0)) cr.fail("height", "must be > 0");
    cr.finish();
    return geometry::Shape::cylinder(cy, Dim);
  }
  if (!e.has("mesh")) return std::nullopt;
  const std::string name = e.string("mesh", "");
  if (Dim != 3) e.fail("mesh", "meshes need \"dimension\": 3 (in 2D use \"sphere\" or \"cylinder\")");
  if (name.empty()) e.fail("mesh", "must name a mesh file (.stl, .obj or .ply)");
  geometry::MeshTransform t;
  t.scale = e.number("scale", 1, 0, 1e9);
  if (!(t.scale > 0)) e.fail("scale", "must be > 0");
  if (e.has("rotate")) {
    auto rr = e.child("rotate");
    const auto ax = rr.required_vector("axis", 3);
    double len = 0;
    for (std::size_t a = 0; a < 3; ++a) {
      t.axis[a] = ax[a];
      len += ax[a] * ax[a];
    }
    if (!(len > 0) || !std::isfinite(len)) rr.fail("axis", "must be a non-zero vector");
    t.angle_deg = rr.required_number("angle", -1e6, 1e6);
    rr.finish();
  }
  const auto tr = e.vector("translate", 3, {0, 0, 0});
  for (std::size_t a = 0; a < 3; ++a) t.translate[a] = tr[a];
  geometry::TriangleMesh m;
  try {
    if (files.builtin) {
      const BuiltinMesh* found = nullptr;
      for (const auto& bm : builtin_meshes())
        if (bm.name == name) found = &bm;
      if (!found) throw InputError(name + ": no such mesh among the built-in scenes' (scenes/meshes/)");
      const auto dot = name.rfind('.');
      m = geometry::parse_mesh(found->data, dot == std::string::npos ? "" : name.substr(dot + 1), name);
    } else {
      const std::filesystem::path p(name);
      m = geometry::read_mesh_file(p.is_absolute() ? p : files.dir / p, name);
    }
    geometry::check_closed(m, name);
  } catch (const InputError& err) {
    e.fail("mesh", err.what());
  }
  geometry::transform(m, t);
  return geometry::Shape::mesh(std::move(m), spacing);
}

// The particles a shape's sampling may make, counted before it runs: its volume (fluid) or a shell of
// `layers` spacings over its surface (walls), and the lattice it walks.
template <int Dim>
void budget_shape(ParticleBudget& budget, const geometry::Shape& s, double spacing, double margin,
                  double estimate, const JsonReader& r, const std::string& key, const std::string& what) {
  budget.take(estimate, r, key, what);
  budget.take_sites(geometry::lattice_sites(s, spacing, margin), r, key, what);
  // The lattice is anchored at the origin: a shape so far from it that its site indices pass 2^50 would
  // overflow them (and has no place in a scene at this spacing anyway).
  for (int a = 0; a < Dim; ++a) budget.check_reach(geometry::lattice_reach(s, margin, a), a, r, key, what);
}

template <int Dim, class Real>
void read_box_boundary(JsonReader& br, double spacing, SolverConfig<Dim, Real>& cfg, Regions<Dim>& regions) {
  if (!br.has("box")) return;
  auto bx = br.child("box");
  const auto b = read_box<Dim>(bx);
  cfg.box.enabled = true;
  cfg.box.lo = to_vec<Dim, Real>(b.lo);
  cfg.box.hi = to_vec<Dim, Real>(b.hi);
  cfg.box.damping = static_cast<Real>(bx.number("damping", double(cfg.box.damping), -1, 0));
  cfg.box.radius = static_cast<Real>(bx.number("radius", spacing / 2, 0, 1e9));
  bx.finish();
  regions.container = b;
}

template <int Dim, class Real>
void read_planes(JsonReader& br, SolverConfig<Dim, Real>& cfg) {
  if (!br.has("planes")) return;
  auto pl = br.child("planes");
  for (std::size_t k = 0; k < pl.array_size(); ++k) {
    auto e = pl.element(k);
    auto n = e.required_vector("normal", Dim);
    const auto pt = e.required_vector("point", Dim);
    double len = 0;
    for (double c : n) len += c * c;
    len = std::sqrt(len);
    if (!(len > 0)) e.fail("normal", "must not be the zero vector");
    Plane<Dim, Real> plane;
    double off = 0;
    for (int a = 0; a < Dim; ++a) {
      plane.normal[a] = static_cast<Real>(n[static_cast<std::size_t>(a)] / len);
      off += n[static_cast<std::size_t>(a)] / len * pt[static_cast<std::size_t>(a)];
    }
    plane.offset = static_cast<Real>(off);
    cfg.planes.push_back(plane);
    e.finish();
  }
}

template <int Dim, class Real>
void read_walls(JsonReader& br, double spacing, const SolverConfig<Dim, Real>& cfg, ParticleBudget& budget,
                Particles<Dim, Real>& p, Regions<Dim>& regions) {
  if (!br.has("walls")) return;
  auto wr = br.child("walls");
  const auto b = read_box<Dim>(wr);
  const int layers = static_cast<int>(wr.integer("layers", 3, 1, 10));
  const bool open_top = wr.boolean("open_top", true);
  // "akinci": the Simulation computes each wall particle's psi_b (Akinci 2012); "volume":
  // rest_density * spacing^dim, right when the wall is at least one support length thick.
  const bool volume = wr.choice("weight", "akinci", {"akinci", "volume"}) == "volume";
  wr.finish();
  const Real weight =
      volume ? cfg.phases[0].rest_density * static_cast<Real>(std::pow(spacing, Dim)) : Real(0);
  // At most the (n + 2 layers)^Dim lattice around the box minus its inside (an open top has fewer).
  double outer = 1, inner = 1;
  for (std::size_t a = 0; a < Dim; ++a) {
    const double n = std::round((b.hi[a] - b.lo[a]) / spacing);
    outer *= n + 2 * layers;
    inner *= n;
  }
  budget.take(outer - inner, br, "walls", "the walls");
  // The open face is the top as gravity sees it (scenes with y up in 3D), not always the last axis.
  int up = Dim - 1;
  for (int a = 0; a < Dim; ++a)
    if (std::abs(cfg.gravity[a]) > std::abs(cfg.gravity[up])) up = a;
  add_box_walls(p, to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), static_cast<Real>(spacing), layers,
                open_top, 0, weight, up);
  regions.container = b;
}

// A shaped obstacle: `layers` layers of boundary particles on the lattice inside its surface, or, with
// "inside": true (a container), outside it.
template <int Dim, class Real>
void add_shape_walls(JsonReader& ob, JsonReader& e, std::size_t k, double spacing, ParticleBudget& budget,
                     Particles<Dim, Real>& p, Regions<Dim>& regions, geometry::Shape shape) {
  const int layers = static_cast<int>(e.integer("layers", 3, 1, 10));
  const bool inside = e.boolean("inside", false);
  e.finish();
  const double depth = layers * spacing;
  const double estimate = 1.5 * shape.area() * depth / std::pow(spacing, Dim) + 8;
  budget_shape<Dim>(budget, shape, spacing, inside ? depth : 0, estimate, ob, std::to_string(k),
                    "this obstacle");
  for (const auto& x : geometry::sample(shape, spacing, inside, depth)) {
    Vec<Dim, Real> v;
    for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(x[static_cast<std::size_t>(a)]);
    add_particle(p, v, 0, ParticleKind::Boundary);
  }
  regions.shape_keys.push_back(e.path());
  regions.all_shapes.push_back(shape);
  regions.shape_margins.push_back(inside ? depth : 0);
  (inside ? regions.container_shapes : regions.solid_shapes).push_back(std::move(shape));
}

// A unit vector of `dim` components at `key` (z = 0 in 2D); the zero vector is an error.
void read_unit(JsonReader& r, const std::string& key, std::size_t dim, double (&out)[3]) {
  const auto v = r.required_vector(key, dim);
  double len = 0;
  for (const double c : v) len += c * c;
  len = std::sqrt(len);
  if (!(len > 0) || !std::isfinite(len)) r.fail(key, "must be a non-zero vector");
  for (std::size_t a = 0; a < 3; ++a) out[a] = a < dim ? v[a] / len : 0.0;
}

// A motion table's text: a file beside the scene (at most 64 MiB); built-in scenes have none.
std::string read_motion_table_file(JsonReader& m, const std::string& name, const MeshFiles& files) {
  if (name.empty()) m.fail("table", "must name a CSV file (columns time,x,y[,z][,angle])");
  if (files.builtin) m.fail("table", "built-in scenes cannot read motion tables");
  const std::filesystem::path p(name);
  const std::filesystem::path file = p.is_absolute() ? p : files.dir / p;
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status)) m.fail("table", name + ": no such file");
  if (std::filesystem::is_directory(status)) m.fail("table", name + ": is a folder, not a CSV file");
  std::ifstream in(file, std::ios::binary);
  if (!in) m.fail("table", name + ": cannot be opened");
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > (std::size_t{64} << 20)) m.fail("table", name + ": is larger than 64 MiB");
  }
  if (in.bad()) m.fail("table", name + ": read error");
  return text;
}

// boundary.obstacles[k].motion (docs/scenes.md, "Moving obstacles"): one of translate, rotate, oscillate
// or table. Returns the motion's index in cfg.wall_motion.motions.
template <int Dim, class Real>
std::int32_t read_motion(JsonReader& e, const MeshFiles& files, SolverConfig<Dim, Real>& cfg) {
  auto mr = e.child("motion");
  if (!mr.json().is_object()) mr.fail_here("expected an object, got " + json_value_text(mr.json()));
  const char* kinds[] = {"translate", "rotate", "oscillate", "table"};
  int given = 0;
  for (const char* k : kinds) given += mr.has(k) ? 1 : 0;
  if (given != 1) {
    std::string keys;
    for (const auto& [key, value] : mr.json().items()) keys += (keys.empty() ? "" : ", ") + key;
    mr.fail_here("give one motion: \"translate\", \"rotate\", \"oscillate\" or \"table\" (got " +
                 (keys.empty() ? std::string("none") : keys) + ")");
  }
  WallMotion m;
  auto start_end = [&](JsonReader& r) {
    m.start = r.number("start", 0, -1e12, 1e12);
    m.end = r.number("end", HUGE_VAL, -1e12, 1e12);
    if (!(m.end >= m.start)) r.fail("end", "must not be before start (" + std::to_string(m.start) + " s)");
  };
  if (mr.has("translate")) {
    m.kind = MotionKind::Translate;
    auto r = mr.child("translate");
    const auto v = r.required_vector("velocity", Dim);
    for (std::size_t a = 0; a < Dim; ++a) m.velocity[a] = v[a];
    start_end(r);
    r.finish();
  } else if (mr.has("rotate")) {
    m.kind = MotionKind::Rotate;
    auto r = mr.child("rotate");
    if (Dim == 3)
      read_unit(r, "axis", 3, m.axis);
    else if (r.has("axis"))
      r.fail("axis",
             "in 2D the rotation is about the out-of-plane axis (positive omega turns x towards y); "
             "leave \"axis\" out");
    const auto c = r.required_vector("center", Dim);
    for (std::size_t a = 0; a < Dim; ++a) m.center[a] = c[a];
    m.omega = r.required_number("omega", -1e6, 1e6);
    start_end(r);
    r.finish();
  } else if (mr.has("oscillate")) {
    m.kind = MotionKind::Oscillate;
    auto r = mr.child("oscillate");
    read_unit(r, "direction", Dim, m.direction);
    m.amplitude = r.required_number("amplitude", -1e9, 1e9);
    if (!(m.amplitude >= 0)) r.fail("amplitude", "must be >= 0 (got " + std::to_string(m.amplitude) + ")");
    m.period = r.required_number("period", -1e12, 1e12);
    if (!(m.period > 0)) r.fail("period", "must be > 0 s (got " + std::to_string(m.period) + ")");
    r.finish();
  } else {
    m.kind = MotionKind::Table;
    const std::string name = mr.string("table", "");
    const std::string text = read_motion_table_file(mr, name, files);
    m.table_begin = static_cast<std::uint32_t>(cfg.wall_motion.rows.size());
    try {
      parse_motion_table(text, name, Dim, cfg.wall_motion.rows);
    } catch (const InputError& err) {
      mr.fail("table", err.what());
    }
    m.table_end = static_cast<std::uint32_t>(cfg.wall_motion.rows.size());
    // The angle column turns about this axis through `center` (moved with the displacement).
    if (Dim == 3 && mr.has("axis")) read_unit(mr, "axis", 3, m.axis);
    const auto c = mr.vector("center", Dim, std::vector<double>(Dim, 0.0));
    for (std::size_t a = 0; a < Dim; ++a) m.center[a] = c[a];
  }
  mr.finish();
  cfg.wall_motion.motions.push_back(m);
  return static_cast<std::int32_t>(cfg.wall_motion.motions.size() - 1);
}

template <int Dim, class Real>
void read_obstacles(JsonReader& br, double spacing, const MeshFiles& files, ParticleBudget& budget,
                    Particles<Dim, Real>& p, Regions<Dim>& regions, SolverConfig<Dim, Real>& cfg) {
  if (!br.has("obstacles")) return;
  auto ob = br.child("obstacles");
  for (std::size_t k = 0; k < ob.array_size(); ++k) {
    auto e = ob.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    const std::size_t first = p.size();
    const std::int32_t motion = e.has("motion") ? read_motion(e, files, cfg) : -1;
    // The obstacle's particles: those added from `first` on.
    auto mark_moving = [&] {
      if (motion < 0) return;
      cfg.wall_motion.of_particle.resize(first, -1);
      cfg.wall_motion.of_particle.resize(p.size(), motion);
    };
    if (auto shape = read_shape<Dim>(e, spacing, files)) {
      add_shape_walls(ob, e, k, spacing, budget, p, regions, std::move(*shape));
      mark_moving();
      continue;
    }
    const auto b = read_box<Dim>(e);
    e.finish();
    const auto n = cells_of<Dim>(b, spacing);
    for (std::size_t a = 0; a < Dim; ++a)
      if (n[a] < 1) e.fail("max", "obstacle is thinner than one particle spacing");
    budget.take(double(n[0]) * double(n[1]) * double(n[2]), ob, std::to_string(k), "this obstacle");
    // A solid block of static boundary particles.
    for (long kk = 0; kk < n[2]; ++kk)
      for (long jj = 0; jj < n[1]; ++jj)
        for (long ii = 0; ii < n[0]; ++ii) {
          const long idx[3] = {ii, jj, kk};
          Vec<Dim, Real> x;
          for (std::size_t a = 0; a < Dim; ++a)
            x[static_cast<int>(a)] = static_cast<Real>(b.lo[a] + (double(idx[a]) + 0.5) * spacing);
          add_particle(p, x, 0, ParticleKind::Boundary);
        }
    regions.solids.push_back(b);
    mark_moving();
  }
}

// Makes the wall and obstacle particles (after the fluid blocks were counted, before they are made).
template <int Dim, class Real>
Regions<Dim> read_boundary(JsonReader& r, double spacing, const MeshFiles& files,
                           SolverConfig<Dim, Real>& cfg, ParticleBudget& budget, Particles<Dim, Real>& p) {
  Regions<Dim> regions;
  if (!r.has("boundary")) return regions;
  auto br = r.child("boundary");
  cfg.no_slip = br.choice("slip", "free", {"free", "no-slip"}) == "no-slip";
  cfg.wall_model = *parse_wall_model(br.choice("model", "akinci", {"akinci", "adami", "dynamic"}));
  read_box_boundary(br, spacing, cfg, regions);
  read_planes(br, cfg);
  read_walls(br, spacing, cfg, budget, p, regions);
  read_obstacles(br, spacing, files, budget, p, regions, cfg);
  br.finish();
  return regions;
}

// --- floating bodies (/bodies, /body_contact) ---------------------------------------------------
// Each body: a box ("box": {min, max}) or a shape (read_shape: "sphere", "cylinder", "mesh"), `layers`
// layers of boundary particles on the lattice inside its surface, its mass and inertia from `density`
// (analytic for a box and a sphere; from the shape's inside lattice, scaled to its exact volume, for a
// cylinder or a mesh), its initial velocity and angular velocity (boundary/rigid_bodies.hpp).
template <int Dim, class Real>
void read_bodies(JsonReader& r, double spacing, const MeshFiles& files, ParticleBudget& budget,
                 Particles<Dim, Real>& p, Regions<Dim>& regions, SolverConfig<Dim, Real>& cfg) {
  auto& rb = cfg.rigid_bodies;
  rb.contact_distance = spacing;
  if (r.has("body_contact")) {
    auto cr = r.child("body_contact");
    rb.contact_distance = cr.number("distance", spacing, 0, 1e9);
    if (!(rb.contact_distance > 0)) cr.fail("distance", "must be > 0");
    rb.contact_frequency = cr.number("frequency", 0, 0, 1e12);
    rb.contact_damping = cr.number("damping", 1, 0, 1e6);
    cr.finish();
  }
  if (!r.has("bodies")) return;
  auto br = r.child("bodies");
  for (std::size_t k = 0; k < br.array_size(); ++k) {
    auto e = br.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    RigidBody body;
    body.density = e.required_number("density", -1e12, 1e12);
    if (!(body.density > 0))
      e.fail("density", "must be > 0 kg/m^3 (got " + json_value_text(e.json()["density"]) + ")");
    const int layers = static_cast<int>(e.integer("layers", 2, 1, 10));
    // As the walls' `weight`: "volume" (rest_density spacing^dim, right for a shell at least one support
    // length thick) or "akinci" (psi_b from the body's own particles).
    const bool weight_volume = e.choice("weight", "volume", {"akinci", "volume"}) == "volume";
    const std::size_t first = p.size();
    double center[3] = {0, 0, 0};
    if (e.has("box")) {
      for (const char* other : {"min", "mesh", "sphere", "cylinder"})
        if (e.has(other)) e.fail_here("give one shape: \"box\", \"sphere\", \"cylinder\" or \"mesh\"");
      auto bx = e.child("box");
      const auto b = read_box<Dim>(bx);
      bx.finish();
      const auto n = cells_of<Dim>(b, spacing);
      double size[3] = {0, 0, 0};
      for (std::size_t a = 0; a < Dim; ++a) {
        if (n[a] < 2)
          e.fail("box", "is thinner than two particle spacings on axis " + std::to_string(a) + " (" +
                            std::to_string(b.hi[a] - b.lo[a]) + " m, spacing " + std::to_string(spacing) +
                            ")");
        size[a] = b.hi[a] - b.lo[a];
        center[a] = 0.5 * (b.lo[a] + b.hi[a]);
      }
      budget.take(double(n[0]) * double(n[1]) * double(n[2]), br, std::to_string(k), "this body");
      for (long kk = 0; kk < n[2]; ++kk)
        for (long jj = 0; jj < n[1]; ++jj)
          for (long ii = 0; ii < n[0]; ++ii) {
            const long idx[3] = {ii, jj, kk};
            bool shell = false;
            Vec<Dim, Real> x;
            for (std::size_t a = 0; a < Dim; ++a) {
              shell = shell || std::min(idx[a], n[a] - 1 - idx[a]) < layers;
              x[static_cast<int>(a)] = static_cast<Real>(b.lo[a] + (double(idx[a]) + 0.5) * spacing);
            }
            if (shell) add_particle(p, x, 0, ParticleKind::Boundary);
          }
      box_mass_properties(Dim, body.density, size, body);
      body.shape = "box";
      // The fluid keeps half a spacing from it as from a shape: in 2D the box is a cylinder's section,
      // in 3D a closed mesh of its 12 triangles.
      geometry::Shape solid = [&] {
        if constexpr (Dim == 2) {
          geometry::Cylinder cy;
          cy.base = {center[0], b.lo[1], 0};
          cy.axis = {0, 1, 0};
          cy.radius = size[0] / 2;
          cy.height = size[1];
          return geometry::Shape::cylinder(cy, 2);
        } else {
          geometry::TriangleMesh m;
          for (int c = 0; c < 8; ++c)
            m.vertices.push_back(
                {(c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], (c & 4) ? b.hi[2] : b.lo[2]});
          m.triangles = {{4, 6, 2}, {4, 2, 0}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
                         {6, 7, 3}, {6, 3, 2}, {2, 3, 1}, {2, 1, 0}, {4, 5, 7}, {4, 7, 6}};
          return geometry::Shape::mesh(std::move(m), spacing);
        }
      }();
      regions.solid_shapes.push_back(std::move(solid));
    } else {
      auto shape = read_shape<Dim>(e, spacing, files);
      if (!shape) e.fail_here("give a shape: \"box\", \"sphere\", \"cylinder\" or \"mesh\"");
      const double depth = layers * spacing;
      budget_shape<Dim>(budget, *shape, spacing, 0, 1.5 * shape->area() * depth / std::pow(spacing, Dim) + 8,
                        br, std::to_string(k), "this body");
      for (const auto& x : geometry::sample(*shape, spacing, false, depth)) {
        Vec<Dim, Real> v;
        for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(x[static_cast<std::size_t>(a)]);
        add_particle(p, v, 0, ParticleKind::Boundary);
      }
      if (e.has("sphere")) {
        const auto& c = e.json()["sphere"]["center"];
        for (std::size_t a = 0; a < Dim; ++a) center[a] = c[a].get<double>();
        ball_mass_properties(Dim, body.density, e.json()["sphere"]["radius"].get<double>(), body);
        body.shape = "sphere";
      } else {
        // The inside lattice's mass and inertia, scaled to the exact volume.
        const auto inside = geometry::sample(*shape, spacing, false, HUGE_VAL);
        std::vector<std::array<double, 3>> pts(inside.begin(), inside.end());
        if (pts.empty()) e.fail_here("holds no lattice site of spacing " + std::to_string(spacing));
        lattice_mass_properties(Dim, body.density, spacing, pts, body, center);
        const double scale = body.density * shape->volume() / body.mass;
        body.mass *= scale;
        for (double& v : body.inertia) v *= scale;
        body.shape = e.has("mesh") ? "mesh" : "cylinder";
      }
      regions.shape_keys.push_back(e.path());
      regions.all_shapes.push_back(*shape);
      regions.shape_margins.push_back(0);
      regions.solid_shapes.push_back(std::move(*shape));
    }
    if (p.size() == first) e.fail_here("has no boundary particle at spacing " + std::to_string(spacing));
    if (weight_volume)
      for (std::size_t i = first; i < p.size(); ++i)
        p.m[i] = cfg.phases[0].rest_density * static_cast<Real>(std::pow(spacing, Dim));
    for (int a = 0; a < 3; ++a) body.initial.x[a] = center[a];
    const auto v = e.vector("velocity", Dim, std::vector<double>(Dim, 0.0));
    for (std::size_t a = 0; a < Dim; ++a) body.initial.v[a] = v[a];
    if (Dim == 2) {
      body.initial.w[2] = e.number("angular_velocity", 0, -1e6, 1e6);
    } else {
      const auto w = e.vector("angular_velocity", 3, {0, 0, 0});
      for (std::size_t a = 0; a < 3; ++a) body.initial.w[a] = w[a];
    }
    e.finish();
    rb.of_particle.resize(first, -1);
    rb.of_particle.resize(p.size(), static_cast<std::int32_t>(rb.bodies.size()));
    rb.bodies.push_back(std::move(body));
  }
}

template <int Dim, class Real>
void read_domain(JsonReader& r, SolverConfig<Dim, Real>& cfg, Regions<Dim>& regions) {
  if (!r.has("domain")) return;
  auto dr = r.child("domain");
  const auto b = read_box<Dim>(dr);
  dr.finish();
  // Every shaped obstacle (with the walls a container puts outside it) must fit the domain.
  for (std::size_t k = 0; k < regions.all_shapes.size(); ++k) {
    const auto& s = regions.all_shapes[k];
    const double m = regions.shape_margins[k];
    for (std::size_t a = 0; a < Dim; ++a)
      if (s.lo()[a] - m < b.lo[a] || s.hi()[a] + m > b.hi[a])
        r.fail("domain", "does not hold the shape of " + regions.shape_keys[k] +
                             " (with its walls): on axis " + std::to_string(a) + " it spans " +
                             std::to_string(s.lo()[a] - m) + " to " + std::to_string(s.hi()[a] + m) +
                             ", the domain " + std::to_string(b.lo[a]) + " to " + std::to_string(b.hi[a]));
  }
  cfg.domain_set = true;
  cfg.domain_lo = to_vec<Dim, Real>(b.lo);
  cfg.domain_hi = to_vec<Dim, Real>(b.hi);
  if (!regions.container) regions.container = b;
}

// A scene without /domain and without a box: the bounding box of its starting particles and emitters,
// grown on every side by the box's longest side (at least 10 spacings). A particle beyond it has flown
// off (an explosion, a jet out of an open tank): the run stops and says so, instead of running on with a
// particle in free flight.
template <int Dim, class Real>
void default_domain(const Particles<Dim, Real>& p, const Inflow& inflow, double spacing,
                    SolverConfig<Dim, Real>& cfg) {
  if (cfg.domain_set || cfg.box.enabled) return;
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  auto grow = [&](int a, double x) {
    lo[a] = std::min(lo[a], x);
    hi[a] = std::max(hi[a], x);
  };
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < Dim; ++a) grow(a, double(p.x[i][a]));
  for (const Emitter& e : inflow.emitters)
    for (int a = 0; a < Dim; ++a) grow(a, e.center[a]);
  if (!(lo[0] <= hi[0])) return;  // nothing to bound
  double side = 10 * spacing;
  for (int a = 0; a < Dim; ++a) side = std::max(side, hi[a] - lo[a]);
  cfg.domain_set = true;
  cfg.domain_default = true;
  for (int a = 0; a < Dim; ++a) {
    cfg.domain_lo[a] = static_cast<Real>(lo[a] - side);
    cfg.domain_hi[a] = static_cast<Real>(hi[a] + side);
  }
}

// --- fluid blocks (/fluids, /initial_pressure) --------------------------------------------------
// The particles the fluid blocks ask for, counted from the JSON as it is (before the boundary, as they are
// most of a scene); a malformed block counts 0 here and is reported by read_fluids.
template <int Dim>
double count_fluid_particles(const nlohmann::json& j, double spacing) {
  double fluid = 0;
  if (j.contains("fluids") && j["fluids"].is_array())
    for (const auto& b : j["fluids"]) {
      if (!b.is_object() || !b.contains("min") || !b.contains("max")) continue;
      const auto &lo = b["min"], &hi = b["max"];
      if (!lo.is_array() || !hi.is_array() || lo.size() != Dim || hi.size() != Dim) continue;
      double n = 1;
      for (std::size_t a = 0; a < Dim; ++a)
        if (lo[a].is_number() && hi[a].is_number())
          n *= std::max(0.0, std::round((hi[a].get<double>() - lo[a].get<double>()) / spacing));
      fluid += n;
    }
  return fluid;
}

template <int Dim>
struct FluidBlocks {
  std::vector<Aabb<Dim>> blocks;
  std::vector<std::int32_t> phase;  // of each block
  // Shaped fluid volumes: their bounds (for the overlap checks), and the particles each made.
  std::vector<Aabb<Dim>> shape_bounds;
  std::vector<std::pair<std::size_t, std::size_t>> shape_ranges;
  std::vector<std::int32_t> shape_phase;
};

// Whether a fluid particle at x keeps half a spacing outside every shaped obstacle and inside some shaped
// container (the box walls' rule: fluid half a spacing from the wall's face).
template <int Dim>
bool clear_of_walls(const geometry::P3& x, const Regions<Dim>& regions, double spacing) {
  const double gap = 0.5 * spacing * (1 - 1e-9);
  for (const auto& s : regions.solid_shapes) {
    const auto side = s.classify(x, gap);
    if (side.sign <= 0 || side.distance < gap) return false;
  }
  if (regions.container_shapes.empty()) return true;
  for (const auto& s : regions.container_shapes) {
    const auto side = s.classify(x, gap);
    if (side.sign < 0 && !(side.distance < gap)) return true;
  }
  return false;
}

// Adds the fluid particles at `xs` that are clear of the shaped walls; returns how many.
template <int Dim, class Real>
std::size_t add_fluid(Particles<Dim, Real>& p, const std::vector<geometry::P3>& xs,
                      const Regions<Dim>& regions, double spacing, std::int32_t phase,
                      const Vec<Dim, Real>& vel) {
  std::vector<std::uint8_t> keep(xs.size(), 1);
  if (!regions.solid_shapes.empty() || !regions.container_shapes.empty())
    parallel_for(xs.size(),
                 [&](std::size_t i) { keep[i] = clear_of_walls(xs[i], regions, spacing) ? 1 : 0; });
  std::size_t added = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    if (!keep[i]) continue;
    Vec<Dim, Real> v;
    for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(xs[i][static_cast<std::size_t>(a)]);
    add_particle(p, v, phase, ParticleKind::Fluid, Real(0), vel);
    ++added;
  }
  return added;
}

template <int Dim, class Real>
FluidBlocks<Dim> read_fluids(JsonReader& r, double spacing, const MeshFiles& files, const PhaseTable& phases,
                             const Regions<Dim>& regions, ParticleBudget& budget, Particles<Dim, Real>& p) {
  if (!r.has("fluids")) r.fail("fluids", "missing (a list of fluid blocks is required)");
  auto fr = r.child("fluids");
  const std::size_t nf = fr.array_size();
  if (nf == 0 && !r.has("emitters")) fr.fail_here("at least one fluid block (or an emitter) is needed");
  FluidBlocks<Dim> out;
  const double tol = 1e-9 * spacing;
  for (std::size_t k = 0; k < nf; ++k) {
    auto e = fr.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    if (auto shape = read_shape<Dim>(e, spacing, files)) {
      const std::int32_t phase = phases.read_reference(e);
      const auto vel = to_vec<Dim, Real>(e.vector("velocity", Dim, filled<Dim>(0)));
      e.finish();
      Aabb<Dim> b{filled<Dim>(0), filled<Dim>(0)};
      for (std::size_t a = 0; a < Dim; ++a) {
        b.lo[a] = shape->lo()[a];
        b.hi[a] = shape->hi()[a];
      }
      for (std::size_t o = 0; o < out.blocks.size(); ++o)
        if (overlap<Dim>(b, out.blocks[o], tol))
          e.fail_here("overlaps fluid block " + std::to_string(o) +
                      " (the bounds of a shaped fluid volume must not)");
      for (std::size_t o = 0; o < out.shape_bounds.size(); ++o)
        if (overlap<Dim>(b, out.shape_bounds[o], tol))
          e.fail_here("overlaps a shaped fluid volume before it (their bounds must not)");
      for (std::size_t o = 0; o < regions.solids.size(); ++o)
        if (overlap<Dim>(b, regions.solids[o], tol))
          e.fail_here("overlaps obstacle " + std::to_string(o) + " of /boundary/obstacles");
      if (regions.container && !inside<Dim>(b, *regions.container, tol))
        e.fail_here("lies (partly) outside the boundary box");
      budget_shape<Dim>(budget, *shape, spacing, 0, 1.1 * shape->volume() / std::pow(spacing, Dim) + 8, fr,
                        std::to_string(k), "this fluid volume");
      const std::size_t first = p.size();
      if (add_fluid(p, geometry::sample(*shape, spacing, false, HUGE_VAL), regions, spacing, phase, vel) == 0)
        e.fail_here("holds no particle: no lattice site of spacing " + std::to_string(spacing) +
                    " lies inside it, half a spacing inside the containers and outside the obstacles");
      out.shape_bounds.push_back(b);
      out.shape_ranges.emplace_back(first, p.size());
      out.shape_phase.push_back(phase);
      continue;
    }
    const auto b = read_box<Dim>(e);
    const std::int32_t phase = phases.read_reference(e);
    const auto vel = to_vec<Dim, Real>(e.vector("velocity", Dim, filled<Dim>(0)));
    e.finish();
    const auto n = cells_of<Dim>(b, spacing);
    for (std::size_t a = 0; a < Dim; ++a)
      if (n[a] < 1)
        e.fail("max", "block holds no particle along axis " + std::to_string(a) + " (extent " +
                          std::to_string(b.hi[a] - b.lo[a]) + " < spacing " + std::to_string(spacing) + ")");
    for (std::size_t o = 0; o < out.blocks.size(); ++o)
      if (overlap<Dim>(b, out.blocks[o], tol))
        e.fail_here("overlaps fluid block " + std::to_string(o) +
                    " (particles would sit on top of each other)");
    for (std::size_t o = 0; o < out.shape_bounds.size(); ++o)
      if (overlap<Dim>(b, out.shape_bounds[o], tol))
        e.fail_here("overlaps a shaped fluid volume before it (their bounds must not)");
    for (std::size_t o = 0; o < regions.solids.size(); ++o)
      if (overlap<Dim>(b, regions.solids[o], tol))
        e.fail_here("overlaps obstacle " + std::to_string(o) + " of /boundary/obstacles");
    if (regions.container && !inside<Dim>(b, *regions.container, tol))
      e.fail_here("lies (partly) outside the boundary box");
    out.blocks.push_back(b);
    out.phase.push_back(phase);
    if (regions.solid_shapes.empty() && regions.container_shapes.empty()) {
      const std::size_t first = p.size();
      add_block(p, to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), static_cast<Real>(spacing), phase);
      for (std::size_t i = first; i < p.size(); ++i) p.v[i] = vel;
      continue;
    }
    // With shaped walls: the block's lattice (add_block's), less what is not clear of them.
    std::vector<geometry::P3> xs;
    xs.reserve(static_cast<std::size_t>(n[0] * n[1] * n[2]));
    for (long kk = 0; kk < n[2]; ++kk)
      for (long jj = 0; jj < n[1]; ++jj)
        for (long ii = 0; ii < n[0]; ++ii) {
          const long idx[3] = {ii, jj, kk};
          geometry::P3 x{0, 0, 0};
          for (std::size_t a = 0; a < Dim; ++a) {
            const auto lo = static_cast<Real>(b.lo[a]);
            x[a] = double(lo + (Real(idx[a]) + Real(0.5)) * static_cast<Real>(spacing));
          }
          xs.push_back(x);
        }
    if (add_fluid(p, xs, regions, spacing, phase, vel) == 0)
      e.fail_here("holds no particle half a spacing inside the containers and outside the obstacles");
  }
  return out;
}

// The hydrostatic pressure of each shaped fluid volume's own weight, rho0 |g| (n + 1/2) spacing for a
// particle with n particles of its volume above it in its lattice column (gravity along an axis).
template <int Dim, class Real>
std::vector<double> shaped_fluid_pressure(const JsonReader& r, double spacing,
                                          const SolverConfig<Dim, Real>& cfg, const FluidBlocks<Dim>& fluids,
                                          const Particles<Dim, Real>& p) {
  std::vector<double> extra(p.size(), 0);
  if (fluids.shape_ranges.empty()) return extra;
  int axis = -1, nonzero = 0;
  for (int a = 0; a < Dim; ++a)
    if (cfg.gravity[a] != 0) {
      axis = a;
      ++nonzero;
    }
  if (nonzero == 0) return extra;
  if (nonzero > 1)
    r.fail("initial_pressure", "\"hydrostatic\" with a shaped fluid volume needs gravity along one axis");
  const double g = std::abs(double(cfg.gravity[axis]));
  const double up = cfg.gravity[axis] < 0 ? 1 : -1;
  for (std::size_t f = 0; f < fluids.shape_ranges.size(); ++f) {
    const auto [first, end] = fluids.shape_ranges[f];
    const double rho0 = double(cfg.phases[static_cast<std::size_t>(fluids.shape_phase[f])].rest_density);
    // Sorted by column, then by height against gravity.
    std::vector<std::pair<std::array<long, 3>, std::size_t>> keys;
    keys.reserve(end - first);
    for (std::size_t i = first; i < end; ++i) {
      std::array<long, 3> k{0, 0, 0};
      int slot = 0;
      for (int a = 0; a < Dim; ++a)
        if (a != axis) k[static_cast<std::size_t>(slot++)] = std::lround(double(p.x[i][a]) / spacing - 0.5);
      k[2] = std::lround(up * double(p.x[i][axis]) / spacing);
      keys.emplace_back(k, i);
    }
    std::sort(keys.begin(), keys.end());
    for (std::size_t c = 0; c < keys.size();) {
      std::size_t e = c;
      while (e < keys.size() && keys[e].first[0] == keys[c].first[0] && keys[e].first[1] == keys[c].first[1])
        ++e;
      for (std::size_t q = c; q < e; ++q)
        extra[keys[q].second] = rho0 * g * (double(e - q - 1) + 0.5) * spacing;
      c = e;
    }
  }
  return extra;
}

template <int Dim, class Real>
void read_initial_pressure(JsonReader& r, double spacing, const SolverConfig<Dim, Real>& cfg,
                           const PhaseTable& phases, const FluidBlocks<Dim>& fluids,
                           Particles<Dim, Real>& p) {
  if (r.choice("initial_pressure", "zero", {"zero", "hydrostatic"}) == "hydrostatic")
    start_hydrostatic(p, cfg, spacing, phases.mass_given, fluids.blocks, fluids.phase,
                      shaped_fluid_pressure(r, spacing, cfg, fluids, p));
}

// --- output (/output) ---------------------------------------------------------------------------
template <int Dim>
void read_output(JsonReader& r, OutputSettings& out) {
  if (!r.has("output")) {
    out.up_axis = Dim - 1;
    return;
  }
  auto orr = r.child("output");
  out.fps = orr.number("fps", out.fps, 1e-6, 1e6);
  if (orr.has("formats")) {
    const auto& fj = orr.json()["formats"];
    if (!fj.is_array()) orr.fail("formats", "expected an array of vtu, ply, csv, got " + json_value_text(fj));
    auto list = orr.child("formats");
    out.formats.clear();
    for (std::size_t k = 0; k < list.array_size(); ++k) {
      const auto& v = fj[k];
      if (!v.is_string() || (v != "vtu" && v != "ply" && v != "csv"))
        list.element(k).fail_here("unknown format " + json_value_text(v) + " (expected vtu, ply or csv)");
      out.formats.push_back(v.get<std::string>());
    }
  }
  out.checkpoint_every = static_cast<int>(orr.integer("checkpoint_every", out.checkpoint_every, 0, 1000000));
  out.color_by = orr.choice("color_by", out.color_by, {"phase", "speed", "pressure"});
  out.up_axis = static_cast<int>(orr.integer("up_axis", Dim - 1, 0, Dim - 1));
  orr.finish();
}

// --- probes (/probes, /probes_every) -------------------------------------------------------------
template <int Dim>
void read_probes(JsonReader& r, std::vector<Probe>& probes, double& every) {
  every = r.number("probes_every", every, 1e-9, 1e9);
  if (!r.has("probes")) return;
  const auto& pj = r.json()["probes"];
  if (!pj.is_array())
    r.fail("probes", "expected an array of {\"name\", \"kind\", \"at\"}, got " + json_value_text(pj));
  auto list = r.child("probes");
  std::vector<std::string> taken{"time"};
  for (std::size_t k = 0; k < list.array_size(); ++k) {
    auto e = list.element(k);
    Probe pr;
    if (!e.has("name")) e.fail("name", "required: the probe's column name in probes.csv");
    pr.name = e.string("name", "");
    if (pr.name.empty() || pr.name.find_first_of(",\"\r\n") != std::string::npos)
      e.fail("name", "'" + pr.name + "' is not a CSV column name (non-empty, no comma, quote or line break)");
    for (const auto& c : probe_columns({pr}, Dim))
      for (const auto& t : taken)
        if (c == t) e.fail("name", "'" + pr.name + "' gives the column '" + c + "', which is already taken");
    if (!e.has("kind")) e.fail("kind", "required: pressure, level, layer or velocity");
    pr.kind = *parse_probe_kind(e.choice("kind", "pressure", {"pressure", "level", "layer", "velocity"}));
    const auto at = e.required_vector("at", Dim);
    for (std::size_t a = 0; a < Dim; ++a) pr.at[a] = at[a];
    e.finish();
    for (const auto& c : probe_columns({pr}, Dim)) taken.push_back(c);
    probes.push_back(std::move(pr));
  }
}

// The box drawn in pictures: the container, else the particles' bounds.
template <int Dim, class Real>
void set_view(Scene<Dim, Real>& s, const std::optional<Aabb<Dim>>& container) {
  std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
  const auto& p = s.particles;
  if (container) {
    for (std::size_t a = 0; a < Dim; ++a) {
      lo[a] = container->lo[a];
      hi[a] = container->hi[a];
    }
  } else {
    for (std::size_t a = 0; a < Dim; ++a) {
      lo[a] = std::numeric_limits<double>::max();
      hi[a] = std::numeric_limits<double>::lowest();
    }
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t a = 0; a < Dim; ++a) {
        lo[a] = std::min(lo[a], double(p.x[i][static_cast<int>(a)]));
        hi[a] = std::max(hi[a], double(p.x[i][static_cast<int>(a)]));
      }
  }
  s.view_lo = lo;
  s.view_hi = hi;
}

// A scene switched to DFSPH or IISPH (`--set /solver/model=dfsph` on a WCSPH scene) may keep settings of
// the other models that they refuse: one message names them all, with the --set edits that make the scene
// fit, rather than one refusal per run (docs/physics.md, "Model 3").
void check_dfsph_fits(const nlohmann::json& j, const std::string& source) {
  const auto at = [](const nlohmann::json& o, const char* key) -> const nlohmann::json* {
    return o.is_object() && o.contains(key) ? &o[key] : nullptr;
  };
  const nlohmann::json* solver = at(j, "solver");
  const nlohmann::json* model = solver ? at(*solver, "model") : nullptr;
  if (!model || (*model != "dfsph" && *model != "iisph")) return;
  const std::string name = *model == "dfsph" ? "DFSPH" : "IISPH";
  std::string what, sets;
  auto add = [&](const std::string& w, const std::string& set) {
    what += what.empty() ? "" : "; ";
    what += w;
    sets += sets.empty() ? "" : " ";
    sets += set;
  };
  const nlohmann::json* boundary = at(j, "boundary");
  if (const nlohmann::json* wm = boundary ? at(*boundary, "model") : nullptr;
      wm && wm->is_string() && *wm != "akinci")
    add("/boundary/model is " + json_value_text(*wm) + " (" + name +
            " holds Akinci 2012 boundary particles only)",
        "--set /boundary/model=akinci");
  const nlohmann::json* av = at(*solver, "artificial_viscosity");
  if (const nlohmann::json* alpha = av ? at(*av, "alpha") : nullptr;
      alpha && alpha->is_number() && alpha->get<double>() > 0)
    add("/solver/artificial_viscosity/alpha is " + json_value_text(*alpha) +
            " (artificial viscosity is part of the WCSPH model)",
        "--set /solver/artificial_viscosity/alpha=0");
  if (const nlohmann::json* d = at(*solver, "density"); d && *d == "continuity")
    add("/solver/density is \"continuity\" (the continuity density is part of the WCSPH model)",
        "--set /solver/density=mass");
  // A DFSPH scene switched to IISPH keeps its /solver/dfsph (IISPH's settings are /solver/iisph).
  if (*model == "iisph" && at(*solver, "dfsph"))
    add("/solver/dfsph is set (DFSPH's settings; IISPH takes its own, /solver/iisph)",
        "--set /solver/dfsph=null");
  if (what.empty()) return;
  throw InputError(source + ": /solver/model = " + json_value_text(*model) +
                   " does not fit this scene's settings: " + what + ". Add: " + sets);
}

}  // namespace

template <int Dim, class Real>
Scene<Dim, Real> load_scene(const nlohmann::json& j, const std::string& source, const SceneLimits& limits) {
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
  check_dfsph_fits(j, source);
  read_solver(r, spacing, cfg);
  read_time(r, cfg, s.output);
  read_neighbors(r, cfg);

  // Particles: counted (fluid blocks first) before each is made, boundary before fluid.
  ParticleBudget budget(Dim, spacing, double(cfg.support) * (1 + double(cfg.verlet_skin)) / spacing,
                        limits.memory_bytes);
  budget.take(count_fluid_particles<Dim>(j, spacing), r, "fluids", "the fluid blocks");
  const MeshFiles files = mesh_files_of(source);
  Regions<Dim> regions = read_boundary(r, spacing, files, cfg, budget, s.particles);
  read_bodies(r, spacing, files, budget, s.particles, regions, cfg);
  read_domain(r, cfg, regions);
  const FluidBlocks<Dim> fluids = read_fluids(r, spacing, files, phases, regions, budget, s.particles);
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
