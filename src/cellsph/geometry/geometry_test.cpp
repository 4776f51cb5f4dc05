// Mesh files and shapes (geometry/mesh.hpp, shape.hpp) against independent references: the analytic
// volume of spheres, cylinders and boxes, the analytic inside of a box (rotated off the lattice), and the
// analytic distance to a sphere's surface for the depth of wall particles. The meshes are the files of
// data/meshes/ (scripts/make_meshes.py).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "cellsph/core/error.hpp"
#include "cellsph/core/test_paths.hpp"
#include "cellsph/geometry/mesh.hpp"
#include "cellsph/geometry/shape.hpp"

namespace cellsph::geometry {
namespace {

const std::filesystem::path kMeshes = std::filesystem::path(cellsph::test::source_dir()) / "data" / "meshes";

std::string error_of(const std::filesystem::path& file) {
  try {
    TriangleMesh m = read_mesh_file(file, file.filename().string());
    check_closed(m, file.filename().string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshFile, EveryFormatGivesTheSameClosedUnitCube) {
  for (const char* f :
       {"cube-ascii.stl", "cube-binary.stl", "cube.obj", "cube-ascii.ply", "cube-binary.ply"}) {
    SCOPED_TRACE(f);
    TriangleMesh m = read_mesh_file(kMeshes / f, f);
    EXPECT_EQ(m.vertices.size(), 8u);  // STL's triangle soup welded into 8 corners
    EXPECT_EQ(m.triangles.size(), 12u);
    ASSERT_NO_THROW(check_closed(m, f));
    EXPECT_DOUBLE_EQ(volume(m), 1.0);
    P3 lo, hi;
    bounds(m, lo, hi);
    EXPECT_EQ(lo, (P3{0, 0, 0}));
    EXPECT_EQ(hi, (P3{1, 1, 1}));
  }
}

TEST(MeshFile, ScaleThenRotateThenTranslate) {
  TriangleMesh m = read_mesh_file(kMeshes / "cube.obj", "cube.obj");
  MeshTransform t;
  t.scale = 2;
  t.axis = {0, 0, 3};  // any length
  t.angle_deg = 90;    // right hand: x -> y
  t.translate = {10, 0, -1};
  transform(m, t);
  check_closed(m, "cube");
  EXPECT_NEAR(volume(m), 8.0, 1e-12);
  P3 lo, hi;
  bounds(m, lo, hi);
  // [0,2]^3 rotated by 90 degrees about z: x in [-2, 0], y in [0, 2]; then translated.
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], (P3{8, 0, -1})[a], 1e-12);
    EXPECT_NEAR(hi[a], (P3{10, 2, 1})[a], 1e-12);
  }
}

TEST(MeshFile, BadFilesNameTheFileAndTheProblem) {
  struct Case {
    const char* file;
    std::vector<std::string> mentions;
  };
  const Case cases[] = {
      // The missing triangle (1, 7, 5) leaves its three edges with one triangle each; the first in the
      // file's order is the top face's edge from (1, 0, 1) to (1, 1, 1), in triangle 3.
      {"open-cube.obj",
       {"open-cube.obj: is not a closed surface", "(1, 0, 1)", "(1, 1, 1)", "triangle 3 only"}},
      {"flipped-triangle-cube.obj",
       {"flipped-triangle-cube.obj: is not consistently oriented", "triangles 3 and 4"}},
      {"zero-volume.obj", {"zero-volume.obj: encloses zero volume"}},
      {"truncated.stl",
       {"truncated.stl: binary STL header announces 12 triangles (684 bytes) but the file has 454 bytes"}},
      {"garbage.stl", {"garbage.stl: binary STL header announces 549083635 triangles", "not an STL file"}},
      {"garbage.obj", {"garbage.obj: "}},
      {"no-such-file.stl", {"no-such-file.stl: no such file"}},
      {"cube.txt", {"cube.txt: unknown mesh format \".txt\""}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string e = error_of(kMeshes / c.file);
    ASSERT_FALSE(e.empty()) << "accepted";
    for (const auto& m : c.mentions) EXPECT_NE(e.find(m), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  }
}

// Polygons are split by us (Assimp's triangulation aborts on some inputs: fuzz/regressions/mesh/).
TEST(MeshFile, QuadsAreSplitIntoTriangles) {
  const std::string quads =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
      "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  TriangleMesh m = parse_mesh(quads, "obj", "quads.obj");
  EXPECT_EQ(m.triangles.size(), 12u);
  ASSERT_NO_THROW(check_closed(m, "quads.obj"));
  EXPECT_DOUBLE_EQ(volume(m), 1.0);
}

// PLY headers are checked before Assimp sees them: it loops without end on one whose end_header is in a
// comment, reserves what the counts announce, and frees memory twice on an element declared twice.
TEST(MeshFile, MalformedPlyHeadersAreRefusedBeforeAssimp) {
  const std::pair<std::string, std::string> cases[] = {
      {"ply\nformat ascii 1.0\ncomment x end_header\n1 0 0\n", "PLY header line 4: unexpected \"1 0 0\""},
      {"ply\nformat ascii 1.0\nelement vertex 1000000000000\nelement face 1\nend_header\n1 2 3\n",
       "announces 1e+12 elements but only 6 bytes follow it"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nend_header\n0 0 0\n1 0 0\n0 1 0\n", "no \"element face\""},
      {"ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header line"},
      {"plx\n", "is not a PLY file"},
      // Assimp 5.2.5 freed memory twice on an element declared twice (fuzz/regressions/mesh).
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement vertex 3\nproperty float x\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0\n0\n1\n2\n3 0 1 2\n",
       "PLY header line 5: element \"vertex\" is declared twice"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty floa x\nelement face 1\nend_header\n0\n1\n2\n3 0 1 "
       "2\n",
       "PLY header line 4: \"property floa x\" is not"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float\nelement face 1\nend_header\n0\n1\n2\n3 0 1 "
       "2\n",
       "PLY header line 4"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty list uchar vertex_indices\nelement face "
       "1\nend_header\n"
       "0\n1\n2\n3 0 1 2\n",
       "PLY header line 4"},
      {"ply\nformat ascii 1.0\nproperty float x\nelement vertex 3\nelement face 1\nend_header\n0\n1\n2\n3 0 "
       "1 2\n",
       "PLY header line 3: a property before any element"},
  };
  for (const auto& [text, mention] : cases) {
    try {
      parse_mesh(text, "ply", "h.ply");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  }
}

TEST(MeshFile, TruncationsOfABinaryStlAreRefusedNeverCrash) {
  std::ifstream in(kMeshes / "cube-binary.stl", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string whole = ss.str();
  for (std::size_t n = 0; n < whole.size(); ++n) {
    EXPECT_THROW(parse_mesh(std::string_view(whole).substr(0, n), "stl", "cut.stl"), InputError)
        << n << " bytes";
  }
  EXPECT_NO_THROW(parse_mesh(whole, "stl", "whole.stl"));
}

// --- shapes ---------------------------------------------------------------------------------------

double sampled_volume(const Shape& s, double spacing) {
  return double(sample(s, spacing, false, HUGE_VAL).size()) * std::pow(spacing, s.dim());
}

TEST(Shape, FluidVolumesMatchTheAnalyticVolumeAt20ParticlesAcross) {
  const double s = 0.1;  // 20 across a unit radius
  const Shape sphere = Shape::sphere({{0.013, -0.021, 0.037}, 1.0}, 3);
  EXPECT_NEAR(sampled_volume(sphere, s) / (4.0 / 3.0 * M_PI), 1.0, 0.02);
  const Shape disc = Shape::sphere({{0.013, -0.021, 0}, 1.0}, 2);
  EXPECT_NEAR(sampled_volume(disc, s) / M_PI, 1.0, 0.02);
  Cylinder c;
  c.base = {0.01, 0.02, 0.03};
  const double n = std::sqrt(3.0);
  c.axis = {1 / n, 1 / n, 1 / n};
  c.radius = 1;
  c.height = 2;
  EXPECT_NEAR(sampled_volume(Shape::cylinder(c, 3), s) / (M_PI * 2), 1.0, 0.02);
  // 2D: the rectangle 2 radius x height through the axis.
  c.axis = {0.6, 0.8, 0};
  const Shape rect = Shape::cylinder(c, 2);
  EXPECT_DOUBLE_EQ(rect.volume(), 4.0);
  EXPECT_NEAR(sampled_volume(rect, s) / 4.0, 1.0, 0.02);

  // Meshes: the unit icosphere (5120 triangles, binary STL) and the cube scaled to 2 m, shifted off the
  // lattice.
  TriangleMesh m = read_mesh_file(kMeshes / "sphere.stl", "sphere.stl");
  check_closed(m, "sphere.stl");
  MeshTransform t;
  t.translate = {0.013, -0.021, 0.037};
  transform(m, t);
  EXPECT_NEAR(sampled_volume(Shape::mesh(m, s), s) / (4.0 / 3.0 * M_PI), 1.0, 0.02);
  TriangleMesh cube = read_mesh_file(kMeshes / "cube-binary.stl", "cube");
  check_closed(cube, "cube");
  t.scale = 2;
  transform(cube, t);
  EXPECT_NEAR(sampled_volume(Shape::mesh(cube, s), s) / 8.0, 1.0, 0.02);
}

// Inside and distance of a mesh against the analytic box it describes, rotated so that its faces cut the
// lattice obliquely, at every lattice site and at random points.
TEST(Shape, MeshInsideAndDistanceMatchTheAnalyticBox) {
  const double s = 0.05, angle = 30 * M_PI / 180;
  TriangleMesh m = read_mesh_file(kMeshes / "cube-ascii.stl", "cube");
  check_closed(m, "cube");
  MeshTransform t;
  t.translate = {-0.5, -0.5, -0.5};
  transform(m, t);  // centred
  t = {};
  t.axis = {0, 0, 1};
  t.angle_deg = 30;
  t.translate = {0.3, 0.2, 0.1};
  transform(m, t);
  const Shape shape = Shape::mesh(m, s);
  // Signed distance to the box, analytic: back to the box's frame.
  auto box_sdf = [&](const P3& p) {
    const double x = p[0] - 0.3, y = p[1] - 0.2, z = p[2] - 0.1;
    const double u = std::cos(angle) * x + std::sin(angle) * y,
                 v = -std::sin(angle) * x + std::cos(angle) * y;
    const double q[3] = {std::abs(u) - 0.5, std::abs(v) - 0.5, std::abs(z) - 0.5};
    double out = 0;
    for (double c : q) out += std::max(c, 0.0) * std::max(c, 0.0);
    return std::sqrt(out) + std::min(std::max({q[0], q[1], q[2]}), 0.0);
  };
  // Every lattice site inside is sampled, none outside.
  const auto inside = sample(shape, s, false, HUGE_VAL);
  std::size_t expected = 0;
  for (long k = -30; k < 30; ++k)
    for (long j = -30; j < 30; ++j)
      for (long i = -30; i < 30; ++i) {
        const P3 p{(double(i) + 0.5) * s, (double(j) + 0.5) * s, (double(k) + 0.5) * s};
        if (box_sdf(p) < -1e-12) ++expected;
        if (std::abs(box_sdf(p)) > 1e-12) {
          EXPECT_EQ(shape.classify(p, 0.2).sign, box_sdf(p) < 0 ? -1 : 1)
              << p[0] << " " << p[1] << " " << p[2];
        }
      }
  EXPECT_EQ(inside.size(), expected);
  for (const auto& p : inside) EXPECT_LT(box_sdf(p), 0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1.2, 1.2);
  for (int n = 0; n < 20000; ++n) {
    const P3 p{U(rng), U(rng), U(rng)};
    const double d = box_sdf(p);
    const Side side = shape.classify(p, 0.2);
    if (std::abs(d) <= 0.2) {
      EXPECT_NEAR(side.distance, std::abs(d), 1e-12);
    } else {
      EXPECT_TRUE(std::isinf(side.distance));
    }
    EXPECT_EQ(side.sign, d < 0 ? -1 : 1);
  }
}

// Lattice rows that run exactly through the mesh's edges and vertices: the unit cube moved so that its
// corners sit on lattice site coordinates (0.05 and 1.05 at spacing 0.1). The rows with y = z run along
// the diagonals of the x faces (an edge of two triangles), others through corners and along face edges. A
// ray through an edge must cross once: the 9^3 sites strictly inside are inside, nothing else is.
TEST(Shape, RowsThroughEdgesAndVerticesCrossOnce) {
  const double s = 0.1;
  TriangleMesh m = read_mesh_file(kMeshes / "cube.obj", "cube.obj");
  check_closed(m, "cube.obj");
  MeshTransform t;
  t.translate = {0.05, 0.05, 0.05};
  transform(m, t);
  const auto inside = sample(Shape::mesh(m, s), s, false, HUGE_VAL);
  EXPECT_EQ(inside.size(), 9u * 9u * 9u);
  for (const auto& p : inside)
    for (double c : p) {
      EXPECT_GT(c, 0.1) << p[0] << " " << p[1] << " " << p[2];
      EXPECT_LT(c, 1.0) << p[0] << " " << p[1] << " " << p[2];
    }
}

// Wall particles: layers inside an obstacle, outside a container, at their requested depth (the
// distance to the analytic sphere within half a spacing of the band (0, layers spacing]), and the band
// without holes.
TEST(Shape, WallLayersSitAtTheirDepthBelowTheAnalyticSurface) {
  const double s = 0.1, R = 1.0;
  const int layers = 3;
  TriangleMesh m = read_mesh_file(kMeshes / "sphere.stl", "sphere.stl");
  check_closed(m, "sphere.stl");
  const Shape mesh = Shape::mesh(m, s), analytic = Shape::sphere({{0, 0, 0}, R}, 3);
  for (const Shape* sh : {&analytic, &mesh}) {
    for (const bool outside : {false, true}) {
      SCOPED_TRACE(std::string(sh == &mesh ? "mesh" : "sphere") + (outside ? " container" : " obstacle"));
      const auto walls = sample(*sh, s, outside, layers * s);
      std::set<std::array<long, 3>> sites;
      for (const auto& p : walls) {
        sites.insert({std::lround(p[0] / s - 0.5), std::lround(p[1] / s - 0.5), std::lround(p[2] / s - 0.5)});
        const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const double depth = outside ? r - R : R - r;  // below the surface on the wall's side
        EXPECT_GT(depth, -0.5 * s);
        EXPECT_LE(depth, layers * s + 0.5 * s);
      }
      // Every site well inside the band is a wall particle (the mesh's facets are within 0.003 of R).
      for (long k = -16; k < 16; ++k)
        for (long j = -16; j < 16; ++j)
          for (long i = -16; i < 16; ++i) {
            const double x = (double(i) + 0.5) * s, y = (double(j) + 0.5) * s, z = (double(k) + 0.5) * s;
            const double r = std::sqrt(x * x + y * y + z * z), depth = outside ? r - R : R - r;
            if (depth > 0.01 && depth < layers * s - 0.01) {
              EXPECT_EQ(sites.count({i, j, k}), 1u) << "hole at " << x << " " << y << " " << z;
            }
          }
      if (sh == &analytic) {
        for (const auto& p : walls) {
          const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
          const double depth = outside ? r - R : R - r;
          EXPECT_GT(depth, 0);
          EXPECT_LE(depth, layers * s * (1 + 1e-12));
        }
      }
    }
  }
}

}  // namespace
}  // namespace cellsph::geometry
