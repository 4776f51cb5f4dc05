// Surfaces are checked against geometry known without the mesher: a lattice ball (disc) of N particles of
// volume s^Dim each fills N s^Dim, so its surface should be the sphere (circle) of that volume; a closed,
// consistently wound mesh uses every edge exactly twice, once in each direction; its enclosed volume
// follows from the divergence theorem. The files are read back with parsers written here.
#include "cellsph/surface/surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>

#include "cellsph/core/error.hpp"
#include "cellsph/io/io_test_util.hpp"

namespace cellsph {
namespace {

constexpr double kSpacing = 0.02;
constexpr double kRho0 = 1000;

template <int Dim, class Real>
void add_test_particle(Particles<Dim, Real>& p, const std::array<double, 3>& x, std::int32_t phase,
                       ParticleKind kind) {
  const std::size_t i = p.size();
  p.resize(i + 1);
  for (int k = 0; k < Dim; ++k) p.x[i][k] = static_cast<Real>(x[k]);
  p.m[i] = static_cast<Real>(kRho0 * std::pow(kSpacing, Dim));
  p.rho[i] = static_cast<Real>(kRho0);
  p.h[i] = static_cast<Real>(2 * kSpacing);
  p.phase[i] = phase;
  p.kind[i] = static_cast<std::uint8_t>(kind);
}

// Lattice points within `radius` of `centre`; phase_of(x) picks each particle's phase.
template <int Dim, class Real, class PhaseOf>
Particles<Dim, Real> ball(const std::array<double, 3>& centre, double radius, PhaseOf phase_of) {
  Particles<Dim, Real> p;
  const int n = static_cast<int>(std::ceil(radius / kSpacing)) + 1;
  const int nz = Dim == 3 ? n : 0;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = -nz; c <= nz; ++c) {
        const double d2 = (a * a + b * b + c * c) * kSpacing * kSpacing;
        if (d2 > radius * radius) continue;
        const std::array<double, 3> x{centre[0] + a * kSpacing, centre[1] + b * kSpacing,
                                      Dim == 3 ? centre[2] + c * kSpacing : 0.0};
        add_test_particle(p, x, phase_of(x), ParticleKind::Fluid);
      }
  return p;
}

struct Mesh {
  std::vector<std::array<double, 3>> v, n;
  std::vector<std::array<std::uint32_t, 3>> f;
};

Mesh from_surface(const SurfaceMesh& s) {
  Mesh m;
  for (std::size_t i = 0; i < s.vertex_count(); ++i) {
    m.v.push_back({s.points[3 * i], s.points[3 * i + 1], s.points[3 * i + 2]});
    m.n.push_back({s.normals[3 * i], s.normals[3 * i + 1], s.normals[3 * i + 2]});
  }
  for (std::size_t t = 0; t < s.triangle_count(); ++t)
    m.f.push_back({s.triangles[3 * t], s.triangles[3 * t + 1], s.triangles[3 * t + 2]});
  return m;
}

// Reads the binary PLY we promise: the header's declared layout is checked line by line.
Mesh read_ply(const std::filesystem::path& path) {
  const std::string data = test::slurp(path);
  const std::size_t end = data.find("end_header\n");
  EXPECT_NE(end, std::string::npos);
  std::istringstream header(data.substr(0, end));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(header, line)) lines.push_back(line);
  EXPECT_GE(lines.size(), 12u);
  EXPECT_EQ(lines[0], "ply");
  EXPECT_EQ(lines[1], "format binary_little_endian 1.0");
  std::size_t nv = 0, nf = 0;
  std::vector<std::string> props;
  for (const auto& l : lines) {
    if (l.rfind("element vertex ", 0) == 0) nv = std::stoul(l.substr(15));
    if (l.rfind("element face ", 0) == 0) nf = std::stoul(l.substr(13));
    if (l.rfind("property ", 0) == 0) props.push_back(l);
  }
  const std::vector<std::string> expected{"property float x",
                                          "property float y",
                                          "property float z",
                                          "property float nx",
                                          "property float ny",
                                          "property float nz",
                                          "property list uchar int vertex_indices"};
  EXPECT_EQ(props, expected);
  Mesh m;
  const char* r = data.data() + end + 11;
  EXPECT_EQ(data.size(), end + 11 + nv * 24 + nf * 13);
  if (data.size() != end + 11 + nv * 24 + nf * 13) return m;
  for (std::size_t i = 0; i < nv; ++i) {
    float rec[6];
    std::memcpy(rec, r, sizeof(rec));
    r += sizeof(rec);
    m.v.push_back({rec[0], rec[1], rec[2]});
    m.n.push_back({rec[3], rec[4], rec[5]});
  }
  for (std::size_t t = 0; t < nf; ++t) {
    EXPECT_EQ(r[0], 3);
    std::int32_t idx[3];
    std::memcpy(idx, r + 1, sizeof(idx));
    r += 13;
    for (auto i : idx) EXPECT_TRUE(i >= 0 && static_cast<std::size_t>(i) < nv);
    m.f.push_back({static_cast<std::uint32_t>(idx[0]), static_cast<std::uint32_t>(idx[1]),
                   static_cast<std::uint32_t>(idx[2])});
  }
  return m;
}

Mesh read_obj(const std::filesystem::path& path) {
  std::ifstream in(path);
  Mesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v" || tag == "vn") {
      std::array<float, 3> a{};  // written as the shortest text of a float: read back as float, exact
      ls >> a[0] >> a[1] >> a[2];
      EXPECT_FALSE(ls.fail()) << line;
      (tag == "v" ? m.v : m.n).push_back({a[0], a[1], a[2]});
    } else if (tag == "f") {
      std::array<std::uint32_t, 3> f{};
      for (auto& i : f) {
        std::string item;
        ls >> item;
        const auto slash = item.find("//");
        EXPECT_NE(slash, std::string::npos) << line;
        EXPECT_EQ(item.substr(0, slash), item.substr(slash + 2)) << line;  // normal index = vertex index
        i = static_cast<std::uint32_t>(std::stoul(item.substr(0, slash)) - 1);
      }
      m.f.push_back(f);
    } else {
      EXPECT_TRUE(tag.empty() || tag == "#") << line;
    }
  }
  return m;
}

std::array<double, 3> sub(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
std::array<double, 3> cross3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Closed and consistently wound: every directed edge occurs once and its reverse once.
void expect_closed(const Mesh& m) {
  ASSERT_FALSE(m.f.empty());
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : m.f)
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  std::size_t bad = 0;
  for (const auto& [e, count] : directed)
    if (count != 1 || directed.count({e.second, e.first}) == 0 || directed.at({e.second, e.first}) != 1)
      ++bad;
  EXPECT_EQ(bad, 0u) << "of " << directed.size() << " directed edges";
  std::vector<int> used(m.v.size(), 0);
  for (const auto& f : m.f)
    for (auto i : f) used[i] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unreferenced vertices";
}

// Divergence theorem: V = 1/3 sum over faces of x . n dA = 1/6 sum a . (b x c).
double enclosed_volume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.f) v += dot3(m.v[f[0]], cross3(m.v[f[1]], m.v[f[2]]));
  return v / 6;
}

template <int Dim, class Real>
void check_ball(const SurfaceOptions& opt) {
  const std::array<double, 3> centre{0.013, -0.007, Dim == 3 ? 0.004 : 0.0};
  const auto p = ball<Dim, Real>(centre, 0.15, [](const auto&) { return 0; });
  const double n = static_cast<double>(p.size());
  const double voxel = kSpacing / 2;
  test::TempDir dir("surface_ball");
  const auto paths = write_surfaces(p, opt, dir.path(), 7);
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_EQ(paths[0].filename().string(),
            opt.format == SurfaceFormat::Ply ? "surface_0_00007.ply" : "surface_0_00007.obj");
  EXPECT_EQ(dir.listing(), std::vector<std::string>{paths[0].filename().string()});  // no temporary left
  const Mesh m = opt.format == SurfaceFormat::Ply ? read_ply(paths[0]) : read_obj(paths[0]);
  ASSERT_EQ(m.v.size(), m.n.size());
  expect_closed(m);

  // The surface bounds the fluid's volume N s^Dim: radius of the ball or disc with that volume.
  const double fluid = n * std::pow(kSpacing, Dim);
  const double radius =
      Dim == 3 ? std::cbrt(fluid * 3 / (4 * std::numbers::pi)) : std::sqrt(fluid / std::numbers::pi);
  const double half = 1.5 * voxel;  // 2D slab: 3 voxels thick by default
  double worst = 0;
  std::size_t inward = 0, sides = 0;
  for (std::size_t i = 0; i < m.v.size(); ++i) {
    auto d = sub(m.v[i], centre);
    if (Dim == 2) {
      EXPECT_LE(std::abs(d[2]), half * (1 + 1e-5));
      if (std::abs(d[2]) > voxel) continue;  // top and bottom of the slab
      d[2] = 0;
      ++sides;
    }
    const double r = std::sqrt(dot3(d, d));
    worst = std::max(worst, std::abs(r - radius));
    if (dot3(m.n[i], d) <= 0) ++inward;
    EXPECT_NEAR(dot3(m.n[i], m.n[i]), 1.0, 1e-5);
  }
  EXPECT_LT(worst, voxel) << "radius " << radius;
  EXPECT_EQ(inward, 0u);
  if (Dim == 2) {
    EXPECT_GT(sides, 100u);
    // The dual mesher bevels the slab's two rims by about half a voxel: ~1% of the volume here.
    EXPECT_NEAR(enclosed_volume(m) / (fluid * 2 * half), 1.0, 0.05);
  } else {
    EXPECT_NEAR(enclosed_volume(m) / fluid, 1.0, 0.03);
  }
  // The 2D slab's top points up, its bottom down.
  if (Dim == 2) {
    for (std::size_t i = 0; i < m.v.size(); ++i) {
      if (std::abs(m.v[i][2]) > half * 0.999 &&
          std::hypot(m.v[i][0] - centre[0], m.v[i][1] - centre[1]) < radius - 2 * voxel) {
        EXPECT_GT(m.n[i][2] * m.v[i][2], 0.0);
      }
    }
  }
}

TEST(Surface, BallIsClosedAtTheFluidRadiusWithOutwardNormals3DDoublePly) {
  check_ball<3, double>({});
}
TEST(Surface, BallIsClosedAtTheFluidRadiusWithOutwardNormals3DFloatObj) {
  SurfaceOptions opt;
  opt.format = SurfaceFormat::Obj;
  check_ball<3, float>(opt);
}
TEST(Surface, DiscBecomesAClosedSlab2DFloatPly) {
  check_ball<2, float>({});
}
TEST(Surface, DiscBecomesAClosedSlab2DDoubleObj) {
  SurfaceOptions opt;
  opt.format = SurfaceFormat::Obj;
  check_ball<2, double>(opt);
}

TEST(Surface, PlyAndObjCarryTheSameMeshAsExtracted) {
  const auto p = ball<3, double>({0, 0, 0}, 0.08, [](const auto&) { return 0; });
  const auto surfaces = extract_surfaces(p, {});
  ASSERT_EQ(surfaces.size(), 1u);
  const Mesh ref = from_surface(surfaces[0].mesh);
  test::TempDir dir("surface_formats");
  write_surface_mesh(surfaces[0].mesh, SurfaceFormat::Ply, dir / "a.ply");
  write_surface_mesh(surfaces[0].mesh, SurfaceFormat::Obj, dir / "a.obj");
  for (const Mesh& m : {read_ply(dir / "a.ply"), read_obj(dir / "a.obj")}) {
    EXPECT_EQ(m.v, ref.v);  // floats written as float bits or shortest round-trip text: exact
    EXPECT_EQ(m.n, ref.n);
    EXPECT_EQ(m.f, ref.f);
  }
}

// The real consumers: VTK's own PLY and OBJ readers (ParaView's), through Debian's python3-vtk9 when
// installed. VTK also says whether the mesh has open or non-manifold edges, and its volume.
TEST(Surface, ReadBackByVtkWhenInstalled) {
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-vtk9 is not installed; the parsers above still check the formats";
  const auto p = ball<3, double>({0, 0, 0}, 0.08, [](const auto&) { return 0; });
  const auto surfaces = extract_surfaces(p, {});
  ASSERT_EQ(surfaces.size(), 1u);
  const auto& mesh = surfaces[0].mesh;
  test::TempDir dir("surface_vtk");
  write_surface_mesh(mesh, SurfaceFormat::Ply, dir / "s.ply");
  write_surface_mesh(mesh, SurfaceFormat::Obj, dir / "s.obj");
  test::spit(
      dir / "read.py",
      "import sys, vtk\n"
      "for name in sys.argv[1:]:\n"
      "    r = vtk.vtkPLYReader() if name.endswith('.ply') else vtk.vtkOBJReader()\n"
      "    r.SetFileName(name)\n"
      "    r.Update()\n"
      "    g = r.GetOutput()\n"
      "    fe = vtk.vtkFeatureEdges()\n"
      "    fe.SetInputData(g)\n"
      "    fe.BoundaryEdgesOn(); fe.NonManifoldEdgesOn(); fe.FeatureEdgesOff(); fe.ManifoldEdgesOff()\n"
      "    fe.Update()\n"
      "    mp = vtk.vtkMassProperties()\n"
      "    mp.SetInputData(g)\n"
      "    mp.Update()\n"
      "    n = g.GetPointData().GetNormals()\n"
      "    print(g.GetNumberOfPoints(), g.GetNumberOfPolys(), n.GetNumberOfTuples() if n else -1,\n"
      "          fe.GetOutput().GetNumberOfCells(), repr(mp.GetVolume()))\n");
  const auto out = dir / "out.txt";
  const std::string cmd = "/usr/bin/python3 " + (dir / "read.py").string() + " " + (dir / "s.ply").string() +
                          " " + (dir / "s.obj").string() + " > " + out.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << test::slurp(out);
  std::istringstream lines(test::slurp(out));
  const double ours = enclosed_volume(from_surface(mesh));
  for (const char* format : {"ply", "obj"}) {
    std::size_t points = 0, polys = 0;
    long normals = 0, open_edges = -1;
    double volume = 0;
    lines >> points >> polys >> normals >> open_edges >> volume;
    ASSERT_FALSE(lines.fail()) << format << ": " << test::slurp(out);
    EXPECT_EQ(points, mesh.vertex_count()) << format;
    EXPECT_EQ(polys, mesh.triangle_count()) << format;
    EXPECT_EQ(static_cast<std::size_t>(normals), mesh.vertex_count()) << format;
    EXPECT_EQ(open_edges, 0) << format;
    EXPECT_NEAR(volume / ours, 1.0, 1e-4) << format;
  }
}

TEST(Surface, TwoPhasesGiveTwoClosedMeshesMeetingAtTheirInterface) {
  // A ball split by the plane x = 0: phase 1 on the left, 4 on the right.
  const auto p = ball<3, double>({0, 0, 0}, 0.12, [](const auto& x) { return x[0] < -1e-9 ? 1 : 4; });
  test::TempDir dir("surface_phases");
  const auto paths = write_surfaces(p, {}, dir.path(), 123456);
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(paths[0].filename().string(), "surface_1_123456.ply");
  EXPECT_EQ(paths[1].filename().string(), "surface_4_123456.ply");
  double total = 0;
  std::size_t count[2] = {0, 0};
  for (std::size_t i = 0; i < p.size(); ++i) ++count[p.phase[i] == 1 ? 0 : 1];
  for (int k = 0; k < 2; ++k) {
    const Mesh m = read_ply(paths[k]);
    expect_closed(m);
    const double vol = enclosed_volume(m);
    // Each phase's colour falls to about 1/4 on the rim where the interface meets the air, so each
    // half-ball's edge is rounded off there (a torus-like sliver of ~s^2 cross-section): 5-8% less.
    EXPECT_NEAR(vol / (static_cast<double>(count[k]) * std::pow(kSpacing, 3)), 1.0, 0.1) << "phase " << k;
    total += vol;
    // Each half stays on its side: the shared sheet lies within a voxel (s/2) of x = -s/2, half-way between
    // the last left column (x = -s) and the first right one (x = 0).
    for (const auto& v : m.v) EXPECT_TRUE(k == 0 ? v[0] < 0 : v[0] > -kSpacing) << v[0];
  }
  EXPECT_NEAR(total / (static_cast<double>(p.size()) * std::pow(kSpacing, 3)), 1.0, 0.1);
}

TEST(Surface, BoundaryParticlesAndEmptyPhasesMakeNoSurface) {
  // Phases 0 and 2 fluid; a wall of boundary particles (phase 0 and phase 1) below the ball.
  auto fluid = ball<3, double>({0, 0, 0}, 0.08, [](const auto& x) { return x[2] > 0.03 ? 2 : 0; });
  auto with_wall = fluid;
  for (int a = -8; a <= 8; ++a)
    for (int b = -8; b <= 8; ++b)
      for (int c = 0; c < 2; ++c)
        add_test_particle(with_wall, {a * kSpacing, b * kSpacing, -0.12 - c * kSpacing}, a < 0 ? 0 : 1,
                          ParticleKind::Boundary);
  test::TempDir dir("surface_boundary");
  const auto paths = write_surfaces(with_wall, {}, dir.path(), 0);
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(paths[0].filename().string(), "surface_0_00000.ply");
  EXPECT_EQ(paths[1].filename().string(), "surface_2_00000.ply");
  EXPECT_EQ(dir.listing().size(), 2u);
  // The wall changes nothing: the meshes equal those of the fluid alone, to the bit.
  const auto alone = extract_surfaces(fluid, {});
  ASSERT_EQ(alone.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const Mesh m = read_ply(paths[k]);
    const Mesh ref = from_surface(alone[k].mesh);
    EXPECT_EQ(m.v, ref.v);
    EXPECT_EQ(m.f, ref.f);
    for (const auto& v : m.v) EXPECT_GT(v[2], -0.1);  // nothing near the wall
  }
  // Only boundary particles: no files at all.
  Particles<3, double> walls;
  add_test_particle(walls, {0, 0, 0}, 0, ParticleKind::Boundary);
  add_test_particle(walls, {kSpacing, 0, 0}, 0, ParticleKind::Boundary);
  test::TempDir dir2("surface_walls");
  EXPECT_TRUE(write_surfaces(walls, {}, dir2.path(), 0).empty());
  EXPECT_TRUE(dir2.listing().empty());
  EXPECT_TRUE(write_surfaces(Particles<2, float>{}, {}, dir2.path(), 0).empty());
}

TEST(Surface, ALoneParticleBelowTheIsoLevelGivesAnEmptyButValidMesh) {
  Particles<3, double> p;
  add_test_particle(p, {0, 0, 0}, 3, ParticleKind::Fluid);  // peak colour s^3 W(0) ~ 0.3 < 1/2
  test::TempDir dir("surface_lone");
  for (auto format : {SurfaceFormat::Ply, SurfaceFormat::Obj}) {
    SurfaceOptions opt;
    opt.format = format;
    const auto paths = write_surfaces(p, opt, dir.path(), 1);
    ASSERT_EQ(paths.size(), 1u);
    const Mesh m = format == SurfaceFormat::Ply ? read_ply(paths[0]) : read_obj(paths[0]);
    EXPECT_TRUE(m.v.empty());
    EXPECT_TRUE(m.f.empty());
  }
}

TEST(Surface, SameInputGivesTheSameBytes) {
  const auto p = ball<3, float>({0.001, 0.002, 0.003}, 0.1, [](const auto& x) { return x[1] > 0 ? 1 : 0; });
  test::TempDir a("surface_det_a"), b("surface_det_b");
  const auto pa = write_surfaces(p, {}, a.path(), 3);
  const auto pb = write_surfaces(p, {}, b.path(), 3);
  ASSERT_EQ(pa.size(), 2u);
  ASSERT_EQ(pb.size(), 2u);
  for (int k = 0; k < 2; ++k) EXPECT_EQ(test::slurp(pa[k]), test::slurp(pb[k]));
}

// OpenVDB meshes with TBB threads: the mesh must not depend on how many.
TEST(Surface, OneThreadOrTwoGiveTheSameMesh) {
  const auto p = ball<3, double>({0.001, 0.002, 0.003}, 0.1, [](const auto& x) { return x[2] > 0 ? 1 : 0; });
  SurfaceOptions o1, o2;
  o1.threads = 1;
  o2.threads = 2;
  const auto one = extract_surfaces(p, o1);
  const auto two = extract_surfaces(p, o2);
  ASSERT_EQ(one.size(), 2u);
  ASSERT_EQ(two.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(one[k].mesh.points, two[k].mesh.points);
    EXPECT_EQ(one[k].mesh.normals, two[k].mesh.normals);
    EXPECT_EQ(one[k].mesh.triangles, two[k].mesh.triangles);
  }
}

TEST(Surface, OptionsChangeTheSurfaceAsDocumented) {
  const auto p = ball<3, double>({0, 0, 0}, 0.1, [](const auto&) { return 0; });
  SurfaceOptions coarse;
  coarse.voxel_size = kSpacing;  // twice the default voxel: about a quarter of the vertices
  const auto fine = extract_surfaces(p, {});
  const auto c = extract_surfaces(p, coarse);
  const double ratio =
      static_cast<double>(c[0].mesh.vertex_count()) / static_cast<double>(fine[0].mesh.vertex_count());
  EXPECT_GT(ratio, 0.15);
  EXPECT_LT(ratio, 0.35);
  // A lower iso level moves the surface out: more volume.
  SurfaceOptions low;
  low.iso = 0.2;
  EXPECT_GT(enclosed_volume(from_surface(extract_surfaces(p, low)[0].mesh)),
            1.05 * enclosed_volume(from_surface(fine[0].mesh)));
}

TEST(Surface, BadInputIsReportedWithTheValue) {
  EXPECT_EQ(parse_surface_format("obj"), SurfaceFormat::Obj);
  EXPECT_THROW(parse_surface_format("stl"), InputError);
  for (auto set : std::vector<void (*)(SurfaceOptions&)>{
           [](SurfaceOptions& o) { o.iso = 1.0; }, [](SurfaceOptions& o) { o.iso = 0.0; },
           [](SurfaceOptions& o) { o.voxel_size = -1; }, [](SurfaceOptions& o) { o.voxel_fraction = 0; },
           [](SurfaceOptions& o) { o.support_scale = std::nan(""); },
           [](SurfaceOptions& o) { o.slab_voxels = 2; }, [](SurfaceOptions& o) { o.threads = -1; }}) {
    SurfaceOptions o;
    set(o);
    EXPECT_THROW(validate(o), InputError);
  }
  try {
    SurfaceOptions o;
    o.iso = 2;
    validate(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("iso = 2"), std::string::npos) << e.what();
  }
  auto p = ball<3, double>({0, 0, 0}, 0.05, [](const auto&) { return 0; });
  SurfaceOptions tiny;
  tiny.voxel_size = 1e-5;
  EXPECT_THROW(extract_surfaces(p, tiny), InputError);
  p.rho[3] = 0;
  EXPECT_THROW(extract_surfaces(p, {}), SimulationError);
  p.rho[3] = kRho0;
  p.x[5][1] = std::nan("");
  EXPECT_THROW(extract_surfaces(p, {}), SimulationError);
}

TEST(Surface, FileNamesPadTheFrameToFiveDigits) {
  EXPECT_EQ(surface_file_name(0, 42, SurfaceFormat::Ply), "surface_0_00042.ply");
  EXPECT_EQ(surface_file_name(12, 123456, SurfaceFormat::Obj), "surface_12_123456.obj");
}

}  // namespace
}  // namespace cellsph
