// The shapes of obstacles, bodies and fluid volumes (docs/scenes.md, "Shapes: meshes, spheres,
// cylinders"): "sphere", "cylinder" or "mesh" (a file beside the scene, or one of the built-in scenes'),
// and where a scene's files are.
#include "cellsph/scene/scene_readers.hpp"

#include <cmath>

#include "cellsph/geometry/mesh.hpp"
#include "cellsph/scene/builtin_scenes.hpp"

namespace cellsph::scene_detail {

MeshFiles mesh_files_of(const std::string& source) {
  std::string s = source;
  if (const auto ed = s.find(" (edited: "); ed != std::string::npos) s.resize(ed);
  if (s.rfind("built-in scene ", 0) == 0) return {true, {}};
  return {false, std::filesystem::path(s).parent_path()};
}

namespace {

template <int Dim>
geometry::Shape read_sphere(JsonReader& e) {
  auto sr = e.child("sphere");
  const auto c = sr.required_vector("center", Dim);
  geometry::Sphere sp;
  for (std::size_t a = 0; a < Dim; ++a) sp.center[a] = c[a];
  sp.radius = sr.required_number("radius", 0, 1e9);
  if (!(sp.radius > 0)) sr.fail("radius", "must be > 0");
  sr.finish();
  return geometry::Shape::sphere(sp, Dim);
}

template <int Dim>
geometry::Shape read_cylinder(JsonReader& e) {
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

// A mesh's "scale", "rotate" and "translate".
geometry::MeshTransform read_mesh_transform(JsonReader& e) {
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
  return t;
}

// The closed mesh `name`: a built-in scene's (scenes/meshes/) or a file beside the scene.
geometry::TriangleMesh load_mesh(JsonReader& e, const std::string& name, const MeshFiles& files) {
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
  return m;
}

template <int Dim>
geometry::Shape read_mesh(JsonReader& e, double spacing, const MeshFiles& files) {
  const std::string name = e.string("mesh", "");
  if (Dim != 3) e.fail("mesh", "meshes need \"dimension\": 3 (in 2D use \"sphere\" or \"cylinder\")");
  if (name.empty()) e.fail("mesh", "must name a mesh file (.stl, .obj or .ply)");
  const geometry::MeshTransform t = read_mesh_transform(e);
  geometry::TriangleMesh m = load_mesh(e, name, files);
  geometry::transform(m, t);
  return geometry::Shape::mesh(std::move(m), spacing);
}

}  // namespace

template <int Dim>
std::optional<geometry::Shape> read_shape(JsonReader& e, double spacing, const MeshFiles& files) {
  int given = 0;
  for (const char* k : {"min", "mesh", "sphere", "cylinder"}) given += e.has(k) ? 1 : 0;
  if (given > 1) e.fail_here("give one shape: \"min\"/\"max\" (a box), \"mesh\", \"sphere\" or \"cylinder\"");
  if (e.has("sphere")) return read_sphere<Dim>(e);
  if (e.has("cylinder")) return read_cylinder<Dim>(e);
  if (!e.has("mesh")) return std::nullopt;
  return read_mesh<Dim>(e, spacing, files);
}

template std::optional<geometry::Shape> read_shape<2>(JsonReader&, double, const MeshFiles&);
template std::optional<geometry::Shape> read_shape<3>(JsonReader&, double, const MeshFiles&);

}  // namespace cellsph::scene_detail
