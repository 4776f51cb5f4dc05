#pragma once
// libFuzzer harness: the mesh files of scenes (geometry/mesh.hpp: STL, OBJ, PLY through Assimp), and
// what a scene does with a mesh that reads: check_closed, a transform, and sampling its inside and a
// wall band on a lattice of an eighth of its size (geometry/shape.hpp). The input's first byte picks the
// format (0: stl, 1: obj, 2: ply, by its value modulo 3); the rest is the file. Bad input must end in
// InputError; anything else (another exception, a crash, a sanitizer report, a leak, a hang) is a finding,
// and so is a read mesh that breaks the reader's promises (finite vertices, triangle indices in range).
// Assimp itself is not instrumented: a memory error inside it shows only when it crashes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "cellsph/geometry/mesh.hpp"
#include "cellsph/geometry/shape.hpp"
#include "fuzz_util.hpp"

namespace cellsph::fuzz {

// One input of the harness (fuzz/mesh_fuzz.cpp); also replayed by fuzz/regressions_test.cpp.
inline void mesh_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  static const char* const kFormats[] = {"stl", "obj", "ply"};
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    geometry::TriangleMesh m = geometry::parse_mesh(bytes, kFormats[data[0] % 3], "mesh");
    for (const auto& v : m.vertices)
      for (double c : v)
        if (!std::isfinite(c)) std::abort();
    for (const auto& t : m.triangles)
      for (auto i : t)
        if (i >= m.vertices.size()) std::abort();
    geometry::check_closed(m, "mesh");
    geometry::MeshTransform tr;
    tr.scale = 1.5;
    tr.axis = {1, 2, 3};
    tr.angle_deg = 40;
    tr.translate = {0.25, -0.5, 1};
    geometry::transform(m, tr);
    geometry::P3 lo, hi;
    geometry::bounds(m, lo, hi);
    double ext = 0;
    for (std::size_t a = 0; a < 3; ++a) ext = std::max(ext, hi[a] - lo[a]);
    if (!(ext > 0) || !std::isfinite(ext)) std::abort();  // check_closed refuses zero volume
    const double spacing = ext / 8;
    const auto shape = geometry::Shape::mesh(std::move(m), spacing);
    const auto inside = geometry::sample(shape, spacing, false, HUGE_VAL);
    const auto walls = geometry::sample(shape, spacing, true, 2 * spacing);
    // At most the lattice's sites, and none twice (sample() walks each site once).
    if (double(inside.size()) > geometry::lattice_sites(shape, spacing, 0) ||
        double(walls.size()) > geometry::lattice_sites(shape, spacing, 2 * spacing))
      std::abort();
  } catch (const InputError&) {
    // bad input, reported as such
  }
}

}  // namespace cellsph::fuzz
