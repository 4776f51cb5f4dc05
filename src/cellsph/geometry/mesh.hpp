#pragma once
// Triangle meshes read from STL (binary and ASCII), OBJ and PLY files with Assimp (Debian's
// libassimp-dev), for scene geometry (docs/scenes.md, "Shapes"). Files are untrusted input: every
// problem (a missing or unreadable file, an unknown extension, a truncated or garbage file, a mesh that
// is not a closed surface or encloses no volume) is an InputError naming the file and the problem, never
// a crash. The mesh is welded (vertices with bit-identical coordinates are one vertex), so an STL file's
// triangle soup becomes a connected surface whose edges can be checked.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace cellsph::geometry {

using P3 = std::array<double, 3>;

struct TriangleMesh {
  std::vector<P3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices, counter-clockwise
                                                        // seen from outside once check_closed passed
};

// Reads a mesh file: the extension (case-insensitive) picks the format: .stl, .obj or .ply. Files above
// 1 GiB are refused. `label` names the file in messages (usually the path as the scene wrote it).
TriangleMesh read_mesh_file(const std::filesystem::path& file, const std::string& label);

// The same from bytes in memory; `extension` is "stl", "obj" or "ply" (the fuzz harness's entry).
TriangleMesh parse_mesh(std::string_view bytes, std::string_view extension, const std::string& label);

// Scale (a factor > 0), then rotate about the origin by `angle_deg` degrees about `axis` (right-hand
// rule; any length > 0), then translate. Applied to every vertex in this order.
struct MeshTransform {
  double scale = 1;
  P3 axis{0, 0, 1};
  double angle_deg = 0;
  P3 translate{0, 0, 0};
};
void transform(TriangleMesh& m, const MeshTransform& t);

// Checks that the mesh is a closed, consistently oriented surface that encloses a volume: every edge
// belongs to exactly two triangles that traverse it in opposite directions. The message names the first
// bad edge (in the order of the file's triangles) by its two vertices' coordinates and the triangle
// (1-based, after polygons are split into fans of triangles from their first vertex). A mesh whose triangles
// face inwards (negative volume) is turned outwards; one that encloses zero volume is refused.
void check_closed(TriangleMesh& m, const std::string& label);

// Signed volume enclosed (divergence theorem): positive when the triangles face outwards.
double volume(const TriangleMesh& m);

// Axis-aligned bounds of the vertices.
void bounds(const TriangleMesh& m, P3& lo, P3& hi);

}  // namespace cellsph::geometry
