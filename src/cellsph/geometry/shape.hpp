#pragma once
// Solid shapes of a scene (spheres, cylinders, closed triangle meshes) and their signed distance,
// sampled on the particle lattice: fluid volumes, walls in layers, and the half spacing fluid keeps from
// every wall (docs/scenes.md, "Shapes"). Distances are exact: analytic for the primitives, the exact
// point-triangle distance for meshes (with the triangles binned in a grid), and a mesh's inside is the
// parity of the crossings of a ray along +x, counted with a tie rule that counts a ray through a shared
// edge or vertex exactly once, so no lattice site is misclassified where it meets the mesh's edges.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "cellsph/geometry/mesh.hpp"

namespace cellsph::geometry {

struct Sphere {
  P3 center{};
  double radius = 0;
};

// A capped cylinder: the disc of `radius` about `base`, perpendicular to `axis` (unit), swept `height`
// along it. In 2D it is its section through the axis: the rectangle of width 2 radius and length height.
struct Cylinder {
  P3 base{}, axis{0, 0, 1};
  double radius = 0, height = 0;
};

class MeshDistance;

// The classification of a point against a shape's surface.
struct Side {
  int sign = 0;                                               // -1 inside, +1 outside, 0 on the surface
  double distance = std::numeric_limits<double>::infinity();  // exact when <= the band asked for, else inf
};

class Shape {
 public:
  static Shape sphere(const Sphere& s, int dim);
  static Shape cylinder(const Cylinder& c, int dim);
  // A closed mesh (check_closed passed); `spacing` sizes the search grids. 3D only.
  static Shape mesh(TriangleMesh m, double spacing);

  // Which side of the surface p lies on, and its distance to the surface when within `band`.
  [[nodiscard]] Side classify(const P3& p, double band) const;
  // Bounds of the solid (z = 0 in 2D).
  [[nodiscard]] const P3& lo() const { return lo_; }
  [[nodiscard]] const P3& hi() const { return hi_; }
  // Its volume (area in 2D): analytic for the primitives, the mesh's enclosed volume.
  [[nodiscard]] double volume() const;
  // Its surface area (perimeter in 2D).
  [[nodiscard]] double area() const;
  [[nodiscard]] int dim() const { return dim_; }

 private:
  enum class Kind { Sphere, Cylinder, Mesh } kind_ = Kind::Sphere;
  int dim_ = 3;
  Sphere sphere_;
  Cylinder cylinder_;
  std::shared_ptr<const MeshDistance> mesh_;
  P3 lo_{}, hi_{};
  friend std::vector<P3> sample(const Shape&, double, bool, double);
  friend std::vector<double> signed_distance_grid(const Shape&, const P3&, double, const std::array<long, 3>&,
                                                  double);
};

// The sites of the global lattice ((i + 1/2) spacing on every axis; z = 0 in 2D) on one side of the
// shape's surface within `depth` of it: inside (outside = false) or outside (true), at a distance
// 0 < d <= depth (depth = infinity: the whole inside). Sites are in lattice order (x fastest), which
// does not depend on the thread count.
std::vector<P3> sample(const Shape& s, double spacing, bool outside, double depth);

// The shape's signed distance (negative inside) at the nodes origin + pitch (i, j, k), i < n[0], j < n[1],
// k < n[2] (n[2] = 1 in 2D), x fastest, clamped to [-band, band]: exact within the band. The nodes' rows
// are computed in parallel, each on its own, so the values do not depend on the thread count.
std::vector<double> signed_distance_grid(const Shape& s, const P3& origin, double pitch,
                                         const std::array<long, 3>& n, double band);

// How many lattice sites sample() looks at (its bounding box of sites), to count before sampling.
double lattice_sites(const Shape& s, double spacing, double margin);

// How far from the origin [m] the lattice sample() walks along `axis` reaches: the farther of the shape's
// faces grown by `margin`.
double lattice_reach(const Shape& s, double margin, int axis);

// The largest lattice_reach / spacing `sample` accepts: its lattice indices are 64-bit integers.
inline constexpr double kMaxLatticeIndex = 0x1p50;

}  // namespace cellsph::geometry
