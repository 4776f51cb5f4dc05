// Cost of one frame's surfaces: a lattice block of N fluid particles (spacing s, support 2s), default
// options (voxel s/2), one phase, extraction only (no file).
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "cellsph/surface/surface.hpp"

namespace cellsph {
namespace {

template <int Dim>
Particles<Dim, float> block(std::size_t n) {
  const double s = 0.01;
  const auto side = static_cast<std::size_t>(std::ceil(std::pow(static_cast<double>(n), 1.0 / Dim)));
  Particles<Dim, float> p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t r = i;
    for (int k = 0; k < Dim; ++k) {
      p.x[i][k] = static_cast<float>(s * static_cast<double>(r % side));
      r /= side;
    }
    p.m[i] = static_cast<float>(1000 * std::pow(s, Dim));
    p.rho[i] = 1000;
    p.h[i] = static_cast<float>(2 * s);
  }
  return p;
}

template <int Dim>
void BM_ExtractSurfaces(benchmark::State& state) {
  const auto p = block<Dim>(static_cast<std::size_t>(state.range(0)));
  std::size_t triangles = 0;
  for (auto _ : state) {
    const auto s = extract_surfaces(p, {});
    triangles = s.at(0).mesh.triangle_count();
    benchmark::DoNotOptimize(triangles);
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_ExtractSurfaces<3>)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExtractSurfaces<2>)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

// The same plus writing the file (PLY binary or OBJ text) into the temporary folder.
template <int Dim>
void BM_WriteSurfaces(benchmark::State& state) {
  const auto p = block<Dim>(static_cast<std::size_t>(state.range(0)));
  SurfaceOptions opt;
  opt.format = state.range(1) == 0 ? SurfaceFormat::Ply : SurfaceFormat::Obj;
  const auto dir = std::filesystem::temp_directory_path() / "cellsph_surface_bench";
  std::filesystem::create_directories(dir);
  for (auto _ : state) benchmark::DoNotOptimize(write_surfaces(p, opt, dir, 0));
  state.SetLabel(opt.format == SurfaceFormat::Ply ? "ply" : "obj");
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteSurfaces<3>)->Args({100000, 0})->Args({100000, 1})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cellsph
