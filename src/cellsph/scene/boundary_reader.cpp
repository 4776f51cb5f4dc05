// /boundary (docs/scenes.md, "boundary"): the write-up's box, the paper's planes, the walls of boundary
// particles, and the obstacles (boxes or shapes, any of them moving).
#include "cellsph/scene/scene_readers.hpp"

#include <cmath>

#include "cellsph/solver/initial.hpp"

namespace cellsph::scene_detail {

namespace {

// Volume-map walls (solver/boundary/bender2019.hpp) are the solids' map: no wall particles.
template <int Dim, class Real>
bool wall_particles(const SolverConfig<Dim, Real>& cfg) {
  return cfg.wall_model != WallModel::VolumeMap;
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
  regions.container_key = bx.path();
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
void read_walls(JsonReader& br, double spacing, SolverConfig<Dim, Real>& cfg, ParticleBudget& budget,
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
  // The open face is the top as gravity sees it (scenes with y up in 3D), not always the last axis.
  int up = Dim - 1;
  for (int a = 0; a < Dim; ++a)
    if (std::abs(cfg.gravity[a]) > std::abs(cfg.gravity[up])) up = a;
  if (wall_particles(cfg)) {
    budget.take(outer - inner, br, "walls", "the walls");
    add_box_walls(p, to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), static_cast<Real>(spacing), layers,
                  open_top, 0, weight, up);
  }
  cfg.guard.container = true;
  cfg.guard.lo = to_vec<Dim, Real>(b.lo);
  cfg.guard.hi = to_vec<Dim, Real>(b.hi);
  cfg.guard.open_axis = open_top ? up : -1;
  regions.container = b;
  regions.container_key = wr.path();
  regions.container_open_axis = open_top ? up : -1;
}

// A shaped obstacle: `layers` layers of boundary particles on the lattice inside its surface, or, with
// "inside": true (a container), outside it; the solid guard keeps the fluid out of it.
template <int Dim, class Real>
void add_shape_walls(JsonReader& ob, JsonReader& e, std::size_t k, double spacing, ParticleBudget& budget,
                     Particles<Dim, Real>& p, Regions<Dim>& regions, geometry::Shape shape,
                     std::int32_t motion, bool particles, SolidGuard<Dim, Real>& guard) {
  const int layers = static_cast<int>(e.integer("layers", 3, 1, 10));
  const bool inside = e.boolean("inside", false);
  e.finish();
  const double depth = layers * spacing;
  const double estimate = 1.5 * shape.area() * depth / std::pow(spacing, Dim) + 8;
  if (particles) {
    budget_shape<Dim>(budget, shape, spacing, inside ? depth : 0, estimate, ob, std::to_string(k),
                      "this obstacle");
    for (const auto& x : geometry::sample(shape, spacing, inside, depth)) {
      Vec<Dim, Real> v;
      for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(x[static_cast<std::size_t>(a)]);
      add_particle(p, v, 0, ParticleKind::Boundary);
    }
  }
  add_guard_grid(shape, spacing, inside, GuardMover{motion, -1}, guard);
  regions.shape_keys.push_back(e.path());
  regions.all_shapes.push_back(shape);
  regions.shape_margins.push_back(inside ? depth : 0);
  (inside ? regions.container_shapes : regions.solid_shapes).push_back(std::move(shape));
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
      add_shape_walls(ob, e, k, spacing, budget, p, regions, std::move(*shape), motion, wall_particles(cfg),
                      cfg.guard);
      mark_moving();
      continue;
    }
    const auto b = read_box<Dim>(e);
    e.finish();
    const auto ax = lattice_of<Dim>(b, spacing, LatticeFit::Solid);
    for (std::size_t a = 0; a < Dim; ++a)
      if (ax[a].n < 1) e.fail("max", "obstacle is thinner than one particle spacing");
    if (wall_particles(cfg))
      budget.take(double(ax[0].n) * double(ax[1].n) * double(ax[2].n), ob, std::to_string(k),
                  "this obstacle");
    // A solid block of static boundary particles.
    for (long kk = 0; kk < (wall_particles(cfg) ? ax[2].n : 0); ++kk)
      for (long jj = 0; jj < ax[1].n; ++jj)
        for (long ii = 0; ii < ax[0].n; ++ii) {
          const long idx[3] = {ii, jj, kk};
          Vec<Dim, Real> x;
          for (std::size_t a = 0; a < Dim; ++a)
            x[static_cast<int>(a)] = static_cast<Real>(ax[a].site(b.lo[a], idx[a]));
          add_particle(p, x, 0, ParticleKind::Boundary);
        }
    regions.solids.push_back(b);
    regions.solid_keys.push_back(e.path());
    cfg.guard.boxes.push_back({to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), GuardMover{motion, -1}});
    mark_moving();
  }
}

}  // namespace

template <int Dim, class Real>
Regions<Dim> read_boundary(JsonReader& r, double spacing, const MeshFiles& files,
                           SolverConfig<Dim, Real>& cfg, ParticleBudget& budget, Particles<Dim, Real>& p) {
  Regions<Dim> regions;
  cfg.guard.depth = static_cast<Real>(kGuardDepth * spacing);
  cfg.guard.margin = static_cast<Real>(kGuardMargin * spacing);
  if (!r.has("boundary")) return regions;
  auto br = r.child("boundary");
  cfg.no_slip = br.choice("slip", "free", {"free", "no-slip"}) == "no-slip";
  cfg.wall_model =
      *parse_wall_model(br.choice("model", "akinci", {"akinci", "adami", "dynamic", "volume-map"}));
  read_box_boundary(br, spacing, cfg, regions);
  read_planes(br, cfg);
  read_walls(br, spacing, cfg, budget, p, regions);
  read_obstacles(br, spacing, files, budget, p, regions, cfg);
  br.finish();
  return regions;
}

#define CELLSPH_BOUNDARY_INSTANTIATE(D, R)                                                            \
  template Regions<D> read_boundary<D, R>(JsonReader&, double, const MeshFiles&, SolverConfig<D, R>&, \
                                          ParticleBudget&, Particles<D, R>&);
CELLSPH_BOUNDARY_INSTANTIATE(2, float)
CELLSPH_BOUNDARY_INSTANTIATE(2, double)
CELLSPH_BOUNDARY_INSTANTIATE(3, float)
CELLSPH_BOUNDARY_INSTANTIATE(3, double)
#undef CELLSPH_BOUNDARY_INSTANTIATE

}  // namespace cellsph::scene_detail
