// Output throughput per format, 3D double particles. Files go to the temp folder (fsync included, as
// in a run).
#include <benchmark/benchmark.h>

#include "cellsph/io/checkpoint.hpp"
#include "cellsph/io/csv_writer.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/io/ply_writer.hpp"
#include "cellsph/io/vtu_writer.hpp"

namespace cellsph {
namespace {

template <class Write>
void run(benchmark::State& state, Write&& write) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto p = test::make_particles<3, double>(n);
  test::TempDir dir("bench");
  const auto file = dir / "out";
  for (auto _ : state) write(p, file);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * std::filesystem::file_size(file)));
}

void BM_WriteVtu(benchmark::State& s) {
  run(s, [](const auto& p, const auto& f) { write_vtu(p, 0.5, f); });
}
void BM_WritePly(benchmark::State& s) {
  run(s, [](const auto& p, const auto& f) { write_ply(p, 0.5, f); });
}
void BM_WriteCsv(benchmark::State& s) {
  run(s, [](const auto& p, const auto& f) { write_csv(p, f); });
}
void BM_WriteCheckpoint(benchmark::State& s) {
  run(s, [](const auto& p, const auto& f) { write_checkpoint(p, {0.5, 10, "state"}, f); });
}
void BM_ReadCheckpoint(benchmark::State& s) {
  const auto n = static_cast<std::size_t>(s.range(0));
  test::TempDir dir("bench_read");
  write_checkpoint(test::make_particles<3, double>(n), {}, dir / "c");
  Particles<3, double> q;
  for (auto _ : s) read_checkpoint(dir / "c", q);
  s.SetItemsProcessed(static_cast<std::int64_t>(s.iterations() * n));
  s.SetBytesProcessed(static_cast<std::int64_t>(s.iterations() * std::filesystem::file_size(dir / "c")));
}

BENCHMARK(BM_WriteVtu)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WritePly)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteCsv)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteCheckpoint)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadCheckpoint)->Arg(200000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cellsph
