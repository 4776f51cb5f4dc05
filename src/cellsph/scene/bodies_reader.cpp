// /bodies and /body_contact (docs/scenes.md, "Floating bodies"). Each body: a box ("box": {min, max}) or a
// shape (read_shape: "sphere", "cylinder", "mesh"), `layers` layers of boundary particles on the lattice
// inside its surface, its mass and inertia from `density` (analytic for a box and a sphere; from the
// shape's inside lattice, scaled to its exact volume, for a cylinder or a mesh), its initial velocity and
// angular velocity (boundary/rigid_bodies.hpp).
#include "cellsph/scene/scene_readers.hpp"

#include <algorithm>
#include <cmath>

#include "cellsph/solver/initial.hpp"

namespace cellsph::scene_detail {

namespace {

// /body_contact: the distance, stiffness and damping of the contact between bodies.
void read_body_contact(JsonReader& r, double spacing, RigidBodies& rb) {
  rb.contact_distance = spacing;
  if (!r.has("body_contact")) return;
  auto cr = r.child("body_contact");
  rb.contact_distance = cr.number("distance", spacing, 0, 1e9);
  if (!(rb.contact_distance > 0)) cr.fail("distance", "must be > 0");
  rb.contact_frequency = cr.number("frequency", 0, 0, 1e12);
  rb.contact_damping = cr.number("damping", 1, 0, 1e6);
  cr.finish();
}

// What every body adds to: the particles, the budget that counts them (its errors name the body in
// /bodies, `list`), the shapes the fluid keeps clear of, and the solid guard.
template <int Dim, class Real>
struct BodyTarget {
  JsonReader& list;
  double spacing;
  const MeshFiles& files;
  ParticleBudget& budget;
  Particles<Dim, Real>& p;
  Regions<Dim>& regions;
  SolidGuard<Dim, Real>& guard;
};

// The shape the fluid keeps half a spacing from a box body, as from a shape: in 2D the box is a
// cylinder's section, in 3D a closed mesh of its 12 triangles.
template <int Dim>
geometry::Shape box_body_shape(const Aabb<Dim>& b, const double (&center)[3], const double (&size)[3],
                               double spacing) {
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
}

// A box body ("box": {min, max}): `layers` layers of boundary particles inside its faces, its mass
// properties and its centre.
template <int Dim, class Real>
void add_box_body(JsonReader& e, std::size_t k, int layers, const BodyTarget<Dim, Real>& t, RigidBody& body,
                  double (&center)[3]) {
  for (const char* other : {"min", "mesh", "sphere", "cylinder"})
    if (e.has(other)) e.fail_here("give one shape: \"box\", \"sphere\", \"cylinder\" or \"mesh\"");
  auto bx = e.child("box");
  const auto b = read_box<Dim>(bx);
  bx.finish();
  const auto ax = lattice_of<Dim>(b, t.spacing, LatticeFit::Solid);
  const long n[3] = {ax[0].n, ax[1].n, ax[2].n};
  double size[3] = {0, 0, 0};
  for (std::size_t a = 0; a < Dim; ++a) {
    if (n[a] < 2)
      e.fail("box", "is thinner than two particle spacings on axis " + std::to_string(a) + " (" +
                        std::to_string(b.hi[a] - b.lo[a]) + " m, spacing " + std::to_string(t.spacing) + ")");
    size[a] = b.hi[a] - b.lo[a];
    center[a] = 0.5 * (b.lo[a] + b.hi[a]);
  }
  t.budget.take(double(n[0]) * double(n[1]) * double(n[2]), t.list, std::to_string(k), "this body");
  for (long kk = 0; kk < n[2]; ++kk)
    for (long jj = 0; jj < n[1]; ++jj)
      for (long ii = 0; ii < n[0]; ++ii) {
        const long idx[3] = {ii, jj, kk};
        bool shell = false;
        Vec<Dim, Real> x;
        for (std::size_t a = 0; a < Dim; ++a) {
          shell = shell || std::min(idx[a], n[a] - 1 - idx[a]) < layers;
          x[static_cast<int>(a)] = static_cast<Real>(ax[a].site(b.lo[a], idx[a]));
        }
        if (shell) add_particle(t.p, x, 0, ParticleKind::Boundary);
      }
  box_mass_properties(Dim, body.density, size, body);
  body.shape = "box";
  t.guard.boxes.push_back(
      {to_vec<Dim, Real>(b.lo), to_vec<Dim, Real>(b.hi), GuardMover{-1, static_cast<std::int32_t>(k)}});
  t.regions.solid_shapes.push_back(box_body_shape<Dim>(b, center, size, t.spacing));
}

// The mass, inertia and centre of a shaped body: analytic for a sphere; for a cylinder or a mesh, those of
// the inside lattice, scaled to the exact volume.
template <int Dim>
void shaped_body_mass(JsonReader& e, const geometry::Shape& shape, double spacing, RigidBody& body,
                      double (&center)[3]) {
  if (e.has("sphere")) {
    const auto& c = e.json()["sphere"]["center"];
    for (std::size_t a = 0; a < Dim; ++a) center[a] = c[a].get<double>();
    ball_mass_properties(Dim, body.density, e.json()["sphere"]["radius"].get<double>(), body);
    body.shape = "sphere";
    return;
  }
  const auto inside = geometry::sample(shape, spacing, false, HUGE_VAL);
  std::vector<std::array<double, 3>> pts(inside.begin(), inside.end());
  if (pts.empty()) e.fail_here("holds no lattice site of spacing " + std::to_string(spacing));
  lattice_mass_properties(Dim, body.density, spacing, pts, body, center);
  const double scale = body.density * shape.volume() / body.mass;
  body.mass *= scale;
  for (double& v : body.inertia) v *= scale;
  body.shape = e.has("mesh") ? "mesh" : "cylinder";
}

// A shaped body: `layers` layers of boundary particles on the lattice inside its surface.
template <int Dim, class Real>
void add_shaped_body(JsonReader& e, std::size_t k, int layers, const BodyTarget<Dim, Real>& t,
                     RigidBody& body, double (&center)[3]) {
  auto shape = read_shape<Dim>(e, t.spacing, t.files);
  if (!shape) e.fail_here("give a shape: \"box\", \"sphere\", \"cylinder\" or \"mesh\"");
  const double depth = layers * t.spacing;
  budget_shape<Dim>(t.budget, *shape, t.spacing, 0,
                    1.5 * shape->area() * depth / std::pow(t.spacing, Dim) + 8, t.list, std::to_string(k),
                    "this body");
  for (const auto& x : geometry::sample(*shape, t.spacing, false, depth)) {
    Vec<Dim, Real> v;
    for (int a = 0; a < Dim; ++a) v[a] = static_cast<Real>(x[static_cast<std::size_t>(a)]);
    add_particle(t.p, v, 0, ParticleKind::Boundary);
  }
  shaped_body_mass<Dim>(e, *shape, t.spacing, body, center);
  add_guard_grid(*shape, t.spacing, false, GuardMover{-1, static_cast<std::int32_t>(k)}, t.guard);
  t.regions.shape_keys.push_back(e.path());
  t.regions.all_shapes.push_back(*shape);
  t.regions.shape_margins.push_back(0);
  t.regions.solid_shapes.push_back(std::move(*shape));
}

// A body's initial velocity and angular velocity (one number in 2D: about the out-of-plane axis).
template <int Dim>
void read_body_velocity(JsonReader& e, RigidBody& body) {
  const auto v = e.vector("velocity", Dim, std::vector<double>(Dim, 0.0));
  for (std::size_t a = 0; a < Dim; ++a) body.initial.v[a] = v[a];
  if (Dim == 2) {
    body.initial.w[2] = e.number("angular_velocity", 0, -1e6, 1e6);
  } else {
    const auto w = e.vector("angular_velocity", 3, {0, 0, 0});
    for (std::size_t a = 0; a < 3; ++a) body.initial.w[a] = w[a];
  }
}

// Body `k` of /bodies, `e`.
template <int Dim, class Real>
void read_body(JsonReader& e, std::size_t k, const BodyTarget<Dim, Real>& t, SolverConfig<Dim, Real>& cfg) {
  RigidBody body;
  body.density = e.required_number("density", -1e12, 1e12);
  if (!(body.density > 0))
    e.fail("density", "must be > 0 kg/m^3 (got " + json_value_text(e.json()["density"]) + ")");
  const int layers = static_cast<int>(e.integer("layers", 2, 1, 10));
  // As the walls' `weight`: "volume" (rest_density spacing^dim, right for a shell at least one support
  // length thick) or "akinci" (psi_b from the body's own particles).
  const bool weight_volume = e.choice("weight", "volume", {"akinci", "volume"}) == "volume";
  const std::size_t first = t.p.size();
  double center[3] = {0, 0, 0};
  if (e.has("box"))
    add_box_body(e, k, layers, t, body, center);
  else
    add_shaped_body(e, k, layers, t, body, center);
  if (t.p.size() == first) e.fail_here("has no boundary particle at spacing " + std::to_string(t.spacing));
  if (weight_volume)
    for (std::size_t i = first; i < t.p.size(); ++i)
      t.p.m[i] = cfg.phases[0].rest_density * static_cast<Real>(std::pow(t.spacing, Dim));
  for (int a = 0; a < 3; ++a) body.initial.x[a] = center[a];
  read_body_velocity<Dim>(e, body);
  e.finish();
  auto& rb = cfg.rigid_bodies;
  rb.of_particle.resize(first, -1);
  rb.of_particle.resize(t.p.size(), static_cast<std::int32_t>(rb.bodies.size()));
  rb.bodies.push_back(std::move(body));
}

}  // namespace

template <int Dim, class Real>
void read_bodies(JsonReader& r, double spacing, const MeshFiles& files, ParticleBudget& budget,
                 Particles<Dim, Real>& p, Regions<Dim>& regions, SolverConfig<Dim, Real>& cfg) {
  read_body_contact(r, spacing, cfg.rigid_bodies);
  if (!r.has("bodies")) return;
  auto br = r.child("bodies");
  const BodyTarget<Dim, Real> target{br, spacing, files, budget, p, regions, cfg.guard};
  for (std::size_t k = 0; k < br.array_size(); ++k) {
    auto e = br.element(k);
    if (!e.json().is_object()) e.fail_here("expected an object, got " + json_value_text(e.json()));
    read_body(e, k, target, cfg);
  }
}

#define CELLSPH_BODIES_INSTANTIATE(D, R)                                                                    \
  template void read_bodies<D, R>(JsonReader&, double, const MeshFiles&, ParticleBudget&, Particles<D, R>&, \
                                  Regions<D>&, SolverConfig<D, R>&);
CELLSPH_BODIES_INSTANTIATE(2, float)
CELLSPH_BODIES_INSTANTIATE(2, double)
CELLSPH_BODIES_INSTANTIATE(3, float)
CELLSPH_BODIES_INSTANTIATE(3, double)
#undef CELLSPH_BODIES_INSTANTIATE

}  // namespace cellsph::scene_detail
