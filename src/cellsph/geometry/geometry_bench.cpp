// Turning a mesh into particles (issue 13: a 100,000-triangle mesh into 10^6 particles, walls and fluid):
// icospheres of 81,920 and 327,680 triangles (levels 6 and 7, the benchmark's argument) written as binary
// STL files, read (Assimp, welding),
// checked closed, and sampled as a fluid volume of about 10^6 particles (radius 62 spacings) and as a
// container's 3 wall layers outside it. Reported per stage; docs/benchmarks.md has the figures.
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "cellsph/geometry/mesh.hpp"
#include "cellsph/geometry/shape.hpp"

namespace cellsph::geometry {
namespace {

constexpr double kSpacing = 1.0 / 62;  // unit sphere: 4/3 pi 62^3 = 998,000 fluid sites

TriangleMesh icosphere(int level) {
  const double p = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh m;
  m.vertices = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  m.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  auto unit = [](P3 v) {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return P3{v[0] / n, v[1] / n, v[2] / n};
  };
  for (auto& v : m.vertices) v = unit(v);
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto at = [&](std::uint32_t a, std::uint32_t b) {
      const auto k = std::minmax(a, b);
      auto it = mid.find(k);
      if (it != mid.end()) return it->second;
      const P3 &x = m.vertices[a], &y = m.vertices[b];
      m.vertices.push_back(unit({(x[0] + y[0]) / 2, (x[1] + y[1]) / 2, (x[2] + y[2]) / 2}));
      return mid[k] = static_cast<std::uint32_t>(m.vertices.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& t : m.triangles) {
      const auto ab = at(t[0], t[1]), bc = at(t[1], t[2]), ca = at(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles = std::move(next);
  }
  return m;
}

// A file removed when the program ends.
struct TempFile {
  std::filesystem::path path;
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

// The icosphere of `level` as a binary STL file in the temp folder (written once per level).
const std::filesystem::path& stl_file(int level = 6) {
  static std::map<int, TempFile> files;
  auto& file = files[level];
  if (!file.path.empty()) return file.path;
  file.path = [level] {
    const auto m = icosphere(level);
    const auto f = std::filesystem::temp_directory_path() /
                   ("cellsph-bench-" + std::to_string(getpid()) + "-" + std::to_string(level) + ".stl");
    std::ofstream out(f, std::ios::binary);
    char header[80] = "cellsph geometry_bench icosphere";
    out.write(header, 80);
    const auto n = static_cast<std::uint32_t>(m.triangles.size());
    out.write(reinterpret_cast<const char*>(&n), 4);
    for (const auto& t : m.triangles) {
      float rec[12] = {0, 0, 0};
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a)
          rec[3 + 3 * v + a] =
              static_cast<float>(m.vertices[t[static_cast<std::size_t>(v)]][static_cast<std::size_t>(a)]);
      out.write(reinterpret_cast<const char*>(rec), sizeof rec);
      const std::uint16_t attr = 0;
      out.write(reinterpret_cast<const char*>(&attr), 2);
    }
    return f;
  }();
  return file.path;
}

void BM_MeshReadAndCheck(benchmark::State& state) {
  for (auto _ : state) {
    TriangleMesh m = read_mesh_file(stl_file(), "icosphere.stl");
    check_closed(m, "icosphere.stl");
    benchmark::DoNotOptimize(m.triangles.data());
  }
}

void BM_MeshToParticles(benchmark::State& state) {
  std::size_t fluid = 0, walls = 0, triangles = 0;
  for (auto _ : state) {
    TriangleMesh m = read_mesh_file(stl_file(static_cast<int>(state.range(0))), "icosphere.stl");
    check_closed(m, "icosphere.stl");
    triangles = m.triangles.size();
    const Shape s = Shape::mesh(std::move(m), kSpacing);
    fluid = sample(s, kSpacing, false, HUGE_VAL).size();
    walls = sample(s, kSpacing, true, 3 * kSpacing).size();
  }
  state.counters["triangles"] = double(triangles);
  state.counters["fluid"] = double(fluid);
  state.counters["walls"] = double(walls);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * (fluid + walls)));
}

// The solid guard's distance grid of the same mesh (scene/solid_guard_grid.cpp): one spacing's pitch over
// its bounds grown by three spacings, exact distances within three spacings of the surface.
void BM_MeshGuardGrid(benchmark::State& state) {
  TriangleMesh m = read_mesh_file(stl_file(static_cast<int>(state.range(0))), "icosphere.stl");
  check_closed(m, "icosphere.stl");
  const Shape s = Shape::mesh(std::move(m), kSpacing);
  const double band = 3 * kSpacing;
  std::array<long, 3> n{};
  P3 origin{};
  for (std::size_t a = 0; a < 3; ++a) {
    origin[a] = s.lo()[a] - band;
    n[a] = static_cast<long>(std::ceil((s.hi()[a] - s.lo()[a] + 2 * band) / kSpacing)) + 1;
  }
  std::size_t nodes = 0;
  for (auto _ : state) {
    const auto grid = signed_distance_grid(s, origin, kSpacing, n, band);
    nodes = grid.size();
    benchmark::DoNotOptimize(grid.data());
  }
  state.counters["nodes"] = double(nodes);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * nodes));
}

BENCHMARK(BM_MeshReadAndCheck)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeshGuardGrid)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshToParticles)->Arg(6)->Arg(7)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace cellsph::geometry
