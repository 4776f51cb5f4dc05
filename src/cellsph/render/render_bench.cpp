// Frame rendering time at the default 1280x720 (2x2 supersampled), particles in a dam-break block.
#include <benchmark/benchmark.h>

#include <cmath>

#include "cellsph/render/renderer.hpp"

namespace cellsph {
namespace {

template <int Dim>
Particles<Dim, float> block(std::size_t n) {
  Particles<Dim, float> p;
  p.resize(n);
  const auto side = static_cast<std::size_t>(std::ceil(std::pow(static_cast<double>(n), 1.0 / Dim)));
  const float dx = 0.5f / static_cast<float>(side);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t r = i;
    for (int k = 0; k < Dim; ++k) {
      p.x[i][k] = dx * (0.5f + static_cast<float>(r % side));
      r /= side;
    }
    p.m[i] = std::pow(dx, static_cast<float>(Dim)) * 1000;
    p.rho[i] = 1000;
    p.phase[i] = p.x[i][0] < 0.25f ? 0 : 1;
  }
  return p;
}

template <int Dim>
void BM_Render(benchmark::State& state) {
  const auto p = block<Dim>(static_cast<std::size_t>(state.range(0)));
  const RenderBox box{{0, 0, 0}, {1, 0.6, 0.5}};
  for (auto _ : state) benchmark::DoNotOptimize(render_image(p, RenderOptions{}, box, 1.0));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * state.range(0)));
}
void BM_EncodePng(benchmark::State& state) {
  const Image img = render_image(block<2>(10000), RenderOptions{}, RenderBox{{0, 0, 0}, {1, 0.6, 0}}, 1.0);
  for (auto _ : state) benchmark::DoNotOptimize(encode_png(img));
}

BENCHMARK(BM_Render<2>)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Render<3>)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodePng)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cellsph
