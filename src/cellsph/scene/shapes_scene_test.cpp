// Shaped obstacles, containers and fluid volumes in scene files (docs/scenes.md, "Shapes"): the particles
// load_scene makes, checked against the analytic shapes (independent of geometry/shape.cpp's distances);
// mesh paths relative to the scene file; the errors that name file and key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "cellsph/core/parallel.hpp"
#include "cellsph/core/test_paths.hpp"
#include "cellsph/probes/probes.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/simulation.hpp"

namespace cellsph {
namespace {

namespace fs = std::filesystem;
const fs::path kMeshes = fs::path(cellsph::test::source_dir()) / "data" / "meshes";

struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    char tmpl[] = "/tmp/cellsph-shapes-XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~ScratchFolder() { fs::remove_all(path); }
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
  ScratchFolder dir;
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

// Still water in the glass: data/meshes/cylinder.stl scaled to radius 0.2 m and height 0.4 m, given as an
// STL container, filled 0.25 m deep, the hydrostatic tank's model (WCSPH, c = 10 sqrt(2 g H), continuity
// density with Fourtakas's diffusion, free-slip Akinci walls, alpha 0.01; docs/scenes.md,
// hydrostatic-tank), run for `steps` steps on 2 threads. Returns the fluid particles that left the glass,
// and the pressure at three heights on the axis and the level there, averaged over the steps after
// `average_from` (every 20th step). The water settles lower than it was filled (the fluid starts half a
// spacing inside the curved wall and spreads up to the wall particles, which the lattice puts anywhere in
// the first spacing outside the surface), so the reference is the hydrostatic law on the level a probe
// measures at the same times, not the solver's own figure.
struct StillGlass {
  std::size_t fluid = 0, outside = 0;
  double level = 0, time = 0;
  std::vector<double> pressure;  // at kGlassHeights
};
const std::vector<double> kGlassHeights{0.04, 0.08, 0.12};

StillGlass still_glass(double spacing, int steps, int average_from) {
  ScratchFolder dir;
  fs::copy_file(kMeshes / "cylinder.stl", dir.path / "glass.stl");
  const double R = 0.2, H = 0.25, g = 9.81, rho0 = 1000, c = 10 * std::sqrt(2 * g * H);
  auto j = nlohmann::json::parse(R"({"dimension": 3, "precision": "double",
      "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.001}],
      "solver": {"model": "wcsph", "density_kernel": "cubic", "pressure_kernel": "cubic",
                 "eos": {"kind": "ratio", "clamp_negative": true}, "gravity": [0, 0, -9.81],
                 "artificial_viscosity": {"alpha": 0.01}, "density": "continuity",
                 "density_diffusion": {"kind": "fourtakas", "delta": 0.1}},
      "time": {"stepping": "courant", "dt_max": 0.001, "courant": 0.3},
      "initial_pressure": "hydrostatic",
      "fluids": [{"min": [-0.25, -0.25, 0], "max": [0.25, 0.25, 0.25]}],
      "boundary": {"slip": "free", "model": "akinci",
                   "obstacles": [{"mesh": "glass.stl", "scale": 0.4, "inside": true, "layers": 2}]}})");
  j["spacing"] = spacing;
  j["solver"]["support"] = 2 * spacing;
  j["solver"]["eos"]["stiffness"] = rho0 * c * c;
  std::ofstream(dir.path / "glass.json") << j.dump();
  auto scene = load_file<3>(dir.path / "glass.json");
  StillGlass out;
  for (const auto k : scene.particles.kind) out.fluid += k == static_cast<std::uint8_t>(ParticleKind::Fluid);
  ScopedThreads two(2);
  Simulation<3, double> sim(scene.solver, scene.particles);
  std::vector<Probe> probes;
  for (std::size_t k = 0; k < kGlassHeights.size(); ++k) {
    Probe pr;
    pr.name = std::vector<std::string>{"lower", "middle", "upper"}[k];
    pr.at = {0, 0, kGlassHeights[k]};
    probes.push_back(pr);
  }
  Probe level;
  level.name = "level";
  level.kind = ProbeKind::Level;
  level.at = {0, 0, 0};
  probes.push_back(level);
  const ProbeSampler<3, double> sampler(probes, KernelKind::CubicSpline, 2 * spacing, spacing);
  std::vector<double> sum(probes.size(), 0.0);
  int samples = 0;
  for (int step = 1; step <= steps; ++step) {
    sim.step();  // a particle leaving the domain or a non-finite value throws SimulationError
    if (step > average_from && step % 20 == 0) {
      const auto v = sampler.sample(sim.particles());
      for (std::size_t k = 0; k < probes.size(); ++k) sum[k] += v[k];
      ++samples;
    }
  }
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == static_cast<std::uint8_t>(ParticleKind::Fluid) &&
        (std::hypot(p.x[i][0], p.x[i][1]) > R || p.x[i][2] < 0))
      ++out.outside;
  out.level = sum.back() / samples;
  for (std::size_t k = 0; k < kGlassHeights.size(); ++k) {
    out.pressure.push_back(sum[k] / samples);
    const double ref = rho0 * g * (out.level - kGlassHeights[k]);
    std::cout << "[glass " << spacing << " m] z " << kGlassHeights[k] << " m: pressure " << out.pressure[k]
              << " Pa, rho0 g (level - z) " << ref << " Pa (level " << out.level << " m), error "
              << 100 * (out.pressure[k] - ref) / (rho0 * g * out.level)
              << "% of rho0 g level (t = " << sim.time() << " s, " << out.fluid << " fluid particles)\n";
  }
  out.time = sim.time();
  return out;
}

// At spacing 0.025 m (16 particles across, 1720 of them), 10^4 steps (about 6.8 s): no fluid particle
// leaves the glass, and the pressure averaged over the last 2000 steps is within 2% of rho0 g level at the
// middle and upper probes (measured -1.6% and -0.1%). The lower one, 1.6 spacings above the floor,
// measured -2.7% and is held to 3% here: at this resolution the settled particles hold part of the
// column's weight on the wall (the gradient between the probes is 7% below rho0 g; walls moved onto
// smooth layers instead of lattice sites measured the same). The issue's 2% at every probe is checked at
// twice the resolution below.
TEST(SceneShapes, ContainerMeshHoldsStillWaterForTenThousandSteps) {
  const auto r = still_glass(0.025, 10000, 8000);
  EXPECT_EQ(r.outside, 0u) << "of " << r.fluid << " fluid particles after " << r.time << " s";
  EXPECT_GT(r.level, 0.8 * 0.25) << "the water level on the axis";
  EXPECT_LT(r.level, 0.25);
  for (std::size_t k = 0; k < kGlassHeights.size(); ++k) {
    const double unit = 1000 * 9.81 * r.level, ref = unit * (1 - kGlassHeights[k] / r.level);
    EXPECT_NEAR(r.pressure[k], ref, (k == 0 ? 0.03 : 0.02) * unit) << "z " << kGlassHeights[k];
  }
}

// The same glass at spacing 0.0125 m (32 particles across, 14,800 of them), settled for 1.5 s and averaged
// over the next second (7400 steps of about 0.34 ms): the pressure at all three heights within the issue's
// 2% of rho0 g level (the CLI's probes measured +0.3%, +1.2%, +0.5% over 1.5-3 s; -1.0%, -0.7%, -0.6% over
// 5.4-6.8 s, docs/scenes.md).
TEST(SceneShapes, ContainerMeshHydrostaticPressureWithinTwoPercent) {
  const auto r = still_glass(0.0125, 7400, 4430);
  EXPECT_EQ(r.outside, 0u) << "of " << r.fluid << " fluid particles after " << r.time << " s";
  EXPECT_GT(r.time, 2.4);
  for (std::size_t k = 0; k < kGlassHeights.size(); ++k) {
    const double unit = 1000 * 9.81 * r.level, ref = unit * (1 - kGlassHeights[k] / r.level);
    EXPECT_NEAR(r.pressure[k], ref, 0.02 * unit) << "z " << kGlassHeights[k];
  }
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
      // Far from the origin: the lattice's site indices would overflow (a fuzzer's find).
      {R"({"spacing": 0.1, "fluids": [{"min": [0,0], "max": [1,1]}],
          "boundary": {"obstacles": [{"sphere": {"center": [-1e107, 0], "radius": 1}}]}})",
       2,
       {"test.json: /boundary/obstacles/0: ", "from the origin along axis 0"}},
      {R"({"spacing": 0.1, "fluids": [{"sphere": {"center": [0, 1e20], "radius": 1}}]})",
       2,
       {"test.json: /fluids/0: ", "from the origin along axis 1"}},
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
