// Shaped obstacles, containers and fluid volumes in scene files (docs/scenes.md, "Shapes"): the particles
// load_scene makes, checked against the analytic shapes (independent of geometry/shape.cpp's distances);
// mesh paths relative to the scene file; the errors that name file and key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "cellsph/scene/scene.hpp"

namespace cellsph {
namespace {

namespace fs = std::filesystem;
const fs::path kMeshes = fs::path(CELLSPH_SOURCE_DIR) / "data" / "meshes";

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/cellsph-shapes-XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

template <int Dim>
Scene<Dim, double> load_file(const fs::path& file) {
  std::string source;
  const auto j = read_scene_json(file.string(), source);
  return load_scene<Dim, double>(j, source);
}

template <int Dim>
Scene<Dim, double> load_text(const std::string& text, const std::string& source = "test.json") {
  return load_scene<Dim, double>(nlohmann::json::parse(text), source);
}

std::string error_of(const std::string& text, int dim, const std::string& source = "test.json") {
  try {
    if (dim == 2)
      load_text<2>(text, source);
    else
      load_text<3>(text, source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The glass: data/meshes/cylinder.stl (radius 0.5, height 1, 64 segments, about +z from the origin),
// named relative to the scene file, as a container holding a box of water cut to it.
TEST(SceneShapes, ContainerMeshHoldsTheFluidHalfASpacingInside) {
  TempDir dir;
  fs::create_directories(dir.path / "meshes");
  fs::copy_file(kMeshes / "cylinder.stl", dir.path / "meshes" / "glass.stl");
  const double s = 0.05;
  std::ofstream(dir.path / "glass.json") << R"({
    "dimension": 3, "spacing": 0.05,
    "solver": {"gravity": [0, 0, -9.81]},
    "initial_pressure": "hydrostatic",
    "fluids": [{"min": [-0.6, -0.6, 0], "max": [0.6, 0.6, 0.5]}],
    "boundary": {"obstacles": [{"mesh": "meshes/glass.stl", "inside": true, "layers": 2}]}
  })";
  const auto sc = load_file<3>(dir.path / "glass.json");
  const auto& p = sc.particles;
  const double R = 0.5, inradius = R * std::cos(M_PI / 64);  // the 64-gon's, 0.4994
  std::size_t fluid = 0, walls = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.x[i][0], y = p.x[i][1], z = p.x[i][2], r = std::hypot(x, y);
    if (p.kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid)) {
      ++fluid;
      EXPECT_LE(r, R - s / 2 + 1e-9) << "fluid outside the glass (or within half a spacing of it)";
      EXPECT_GE(z, s / 2 - 1e-9);
      EXPECT_LE(z, 1 - s / 2 + 1e-9);
    } else {
      ++walls;
      // Outside the 64-gon, at most 2 layers (+ half a spacing) beyond the cylinder.
      EXPECT_TRUE(r > inradius || z < 0 || z > 1) << x << " " << y << " " << z;
      const double out_r = std::max(r - R, 0.0), out_z = std::max({-z, z - 1, 0.0});
      EXPECT_LE(std::hypot(out_r, out_z), 2 * s + s / 2);
    }
  }
  // The fluid fills the glass up to 0.5 m less half a spacing all round: pi (R - s/2)^2 (0.5 - s/2).
  const double expected = M_PI * (R - s / 2) * (R - s / 2) * (0.5 - s / 2) / (s * s * s);
  EXPECT_NEAR(double(fluid) / expected, 1.0, 0.03) << fluid << " fluid particles";
  EXPECT_GT(walls, 0u);
}

TEST(SceneShapes, SphereObstacleAndFluidVolumesIn2DAnd3D) {
  // 3D: a sphere obstacle in a box of water; the water keeps half a spacing from it, the walls sit in the
  // 2 layers below its surface.
  const double s = 0.05;
  const auto sc = load_text<3>(R"({
    "dimension": 3, "spacing": 0.05,
    "fluids": [{"min": [0, 0, 0], "max": [1, 1, 1]}],
    "boundary": {"obstacles": [{"sphere": {"center": [0.5, 0.5, 0.4], "radius": 0.2}, "layers": 2}]}
  })");
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < sc.particles.size(); ++i) {
    const auto& x = sc.particles.x[i];
    const double d =
        std::sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5) + (x[2] - 0.4) * (x[2] - 0.4));
    if (sc.particles.kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid)) {
      ++fluid;
      EXPECT_GE(d, 0.2 + s / 2 - 1e-9);
    } else {
      EXPECT_GT(d, 0.2 - 2 * s - 1e-9);
      EXPECT_LT(d, 0.2);
    }
  }
  // The box less the sphere grown by half a spacing.
  const double expected = (1 - 4.0 / 3.0 * M_PI * std::pow(0.2 + s / 2, 3)) / (s * s * s);
  EXPECT_NEAR(double(fluid) / expected, 1.0, 0.02);

  // 2D: a disc of water (20 particles across) and a rectangle ("cylinder" in 2D) of water.
  const auto s2 = load_text<2>(R"({
    "spacing": 0.05,
    "fluids": [{"sphere": {"center": [0.5, 0.5], "radius": 0.5}, "velocity": [1, 0]},
               {"cylinder": {"base": [2, 0], "axis": [0, 1], "radius": 0.25, "height": 1}}]
  })");
  std::size_t disc = 0, rect = 0;
  for (std::size_t i = 0; i < s2.particles.size(); ++i) {
    const auto& x = s2.particles.x[i];
    if (x[0] < 1.5) {
      ++disc;
      EXPECT_LT(std::hypot(x[0] - 0.5, x[1] - 0.5), 0.5);
      EXPECT_EQ(s2.particles.v[i][0], 1.0);
    } else {
      ++rect;
      EXPECT_LT(std::abs(x[0] - 2), 0.25);
      EXPECT_GT(x[1], 0);
      EXPECT_LT(x[1], 1);
    }
  }
  EXPECT_NEAR(double(disc) * s * s / (M_PI * 0.25), 1.0, 0.02);
  EXPECT_EQ(rect, 10u * 20u);
}

// A fluid volume from a mesh (the unit icosphere, scaled to radius 0.5 m: 20 particles across) starts
// hydrostatic: a particle's pressure is rho0 g times the depth of the column of its volume above it.
TEST(SceneShapes, MeshFluidVolumeHasTheSphereVolumeAndAHydrostaticStart) {
  const double s = 0.05;
  const std::string scene = R"({
    "dimension": 3, "spacing": 0.05,
    "solver": {"gravity": [0, -10, 0]},
    "initial_pressure": "hydrostatic",
    "fluids": [{"mesh": ")" +
                            (kMeshes / "sphere.stl").string() +
                            R"(", "scale": 0.5, "translate": [0.01, 0.02, 0.03]}]
  })";
  const auto sc = load_text<3>(scene);
  const auto& p = sc.particles;
  EXPECT_NEAR(double(p.size()) * s * s * s / (4.0 / 3.0 * M_PI * 0.125), 1.0, 0.02);
  // The central column: its lowest particle has n particles above it and the pressure rho0 g (n + 1/2) s,
  // its highest 1/2 s of water; the masses are rho(p) times one volume, with Tait's rho(p) = rho0 (1 +
  // p / k)^(1/7) (k = 1000 Pa, the default).
  std::size_t low = p.size(), high = p.size(), n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(p.x[i][0] - 0.025) > 1e-9 || std::abs(p.x[i][2] - 0.025) > 1e-9) continue;
    ++n;
    if (low == p.size() || p.x[i][1] < p.x[low][1]) low = i;
    if (high == p.size() || p.x[i][1] > p.x[high][1]) high = i;
  }
  ASSERT_GE(n, 18u);  // the sphere is 20 spacings tall
  const double p_low = 1000 * 10 * (double(n - 1) + 0.5) * s, p_high = 1000 * 10 * 0.5 * s;
  EXPECT_NEAR(p.m[low] / p.m[high], std::pow((1 + p_low / 1000) / (1 + p_high / 1000), 1.0 / 7), 1e-9);
}

TEST(SceneShapes, ErrorsNameTheKeyAndTheFile) {
  struct Case {
    std::string text;
    int dim;
    std::vector<std::string> mentions;
  };
  const std::string open = (kMeshes / "open-cube.obj").string();
  const std::string garbage = (kMeshes / "garbage.stl").string();
  const Case cases[] = {
      {R"({"spacing": 0.1, "fluids": [{"min": [0,0], "max": [1,1]}],
          "boundary": {"obstacles": [{"mesh": "x.stl"}]}})",
       2,
       {"test.json: /boundary/obstacles/0/mesh: meshes need \"dimension\": 3"}},
      {R"({"dimension": 3, "spacing": 0.1, "fluids": [{"min": [0,0,0], "max": [1,1,1]}],
          "boundary": {"obstacles": [{"mesh": ")" +
           open + R"(", "scale": 0.1}]}})",
       3,
       {"test.json: /boundary/obstacles/0/mesh: ", "open-cube.obj: is not a closed surface", "(1, 1, 1)"}},
      {R"({"dimension": 3, "spacing": 0.1, "fluids": [{"mesh": ")" + garbage + R"("}]})",
       3,
       {"test.json: /fluids/0/mesh: ", "garbage.stl: binary STL header announces"}},
      {R"({"dimension": 3, "spacing": 0.1, "fluids": [{"mesh": "nowhere/none.ply"}]})",
       3,
       {"test.json: /fluids/0/mesh: nowhere/none.ply: no such file"}},
      {R"({"spacing": 0.1, "fluids": [{"min": [0,0], "max": [1,1], "sphere": {"center": [0,0], "radius": 1}}]})",
       2,
       {"test.json: /fluids/0: give one shape"}},
      {R"({"spacing": 0.1, "fluids": [{"sphere": {"center": [0,0], "radius": 0}}]})",
       2,
       {"test.json: /fluids/0/sphere/radius"}},
      {R"({"spacing": 0.1, "fluids": [{"cylinder": {"base": [0,0], "axis": [0,0], "radius": 1, "height": 1}}]})",
       2,
       {"test.json: /fluids/0/cylinder/axis: must be a non-zero vector"}},
      {R"({"spacing": 0.1, "fluids": [{"min": [0,0], "max": [1,1]}],
          "boundary": {"obstacles": [{"sphere": {"center": [0,0], "radius": 1}, "layers": 2, "inside": true}]},
          "domain": {"min": [-1, -1], "max": [1, 1]}})",
       2,
       {"test.json: /domain: does not hold the shape of /boundary/obstacles/0"}},
      {R"({"spacing": 0.1, "fluids": [{"sphere": {"center": [5,5], "radius": 0.5}}],
          "boundary": {"obstacles": [{"sphere": {"center": [0,0], "radius": 1}, "inside": true}]}})",
       2,
       {"test.json: /fluids/0: holds no particle"}},
      {R"({"spacing": 1e-4, "fluids": [{"sphere": {"center": [0,0], "radius": 1000}}]})",
       2,
       {"test.json: /fluids/0: ", "particles"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string e = error_of(c.text, c.dim);
    ASSERT_FALSE(e.empty()) << "accepted";
    for (const auto& m : c.mentions) EXPECT_NE(e.find(m), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace cellsph
