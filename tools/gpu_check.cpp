// The program of scripts/gpu_check.sh (built by cmake/gpu_check.cmake on a GPU machine): compares the CUDA
// backend with the CPU and times it. Writes a plain-text report to stdout (the script keeps it).
//  1. device: the CUDA device report (exit 2 without a usable device);
//  2. steps: the built-in scenes of compare_backends (WCSPH, the paper model, DFSPH in 2D and 3D, a moving
//     wall, inflow, a floating body), N steps on each backend; positions compared (bit-identical count,
//     largest difference relative to the domain) against the stated tolerances;
//  3. rows: on each scene's final state, the device grid's neighbour rows against the CPU search (every
//     method gives the same CSR rows): they must be equal, exactly;
//  4. bench: the 3D dam break rescaled to each requested fluid count (as `cellsph bench sph`), warm-up
//     steps, then timed steps: ms per step, the neighbour share, fluid particle-steps per second, wall
//     time per simulated second, device memory per particle; the CPU (all cores) at the smallest size
//     for the ratio; then (--dfsph-until) dam-break-3d-dfsph from rest on both backends.
// --host-device runs it all on the host-emulated device (no GPU needed); --bench-only skips 2 and 3.
// First run on an H200 on 2026-12-04: docs/gpu.md, "Measured on an H200".

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/timer.hpp"
#include "cellsph/neighbors/neighbor_search.hpp"
#include "cellsph/scene/scene.hpp"
#include "cellsph/solver/backend.hpp"
#include "cellsph/solver/device/device_stepper_base.hpp"
#include "cellsph/solver/simulation.hpp"

namespace {

using namespace cellsph;

int g_failures = 0;
// The device under check: CUDA, or (--host-device) the host-emulated device, to try this program on a
// machine without a GPU before device time is spent on it.
Backend g_device = Backend::Cuda;

// A stepper of the device under check.
template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_device(const SolverConfig<Dim, Real>& cfg) {
  return g_device == Backend::Cuda ? make_cuda_stepper(cfg) : make_host_device_stepper(cfg);
}

void verdict(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "PASS" : "FAIL", what.c_str());
  std::fflush(stdout);
  if (!ok) ++g_failures;
}

template <int Dim, class Real>
Scene<Dim, Real> scene_of(const nlohmann::json& j) {
  return load_scene<Dim, Real>(j, "gpu_check");
}

// The device's rows equal the CPU search's on these particles (fluid rows: every neighbour; wall rows:
// the fluid ones).
template <int Dim, class Real>
bool rows_equal(const SolverConfig<Dim, Real>& cfg, const Particles<Dim, Real>& p, std::uint64_t& pairs) {
  auto dev = make_device(cfg);
  dev->upload(p);
  const DeviceRows d = dev->neighbor_rows();
  NeighborSearch<Dim, Real> search(cfg.search);
  NeighborList nl;
  search.build(std::span<const Vec<Dim, Real>>(p.x), std::span<const Real>(p.h));
  search.find_all(nl);
  const bool walls = !d.wall_start.empty();
  pairs = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::vector<std::uint32_t> want(nl.indices.begin() + static_cast<std::ptrdiff_t>(nl.offsets[i]),
                                    nl.indices.begin() + static_cast<std::ptrdiff_t>(nl.offsets[i + 1]));
    std::vector<std::uint32_t> got;
    if (p.kind[i] == 0) {
      got.assign(d.rows.begin() + static_cast<std::ptrdiff_t>(d.offsets[i]),
                 d.rows.begin() + static_cast<std::ptrdiff_t>(d.offsets[i] + d.count[i]));
    } else {
      if (!walls) continue;
      std::erase_if(want, [&](std::uint32_t j) { return p.kind[j] != 0; });
      got.assign(d.wall_rows.begin() + d.wall_start[i], d.wall_rows.begin() + d.wall_start[i + 1]);
    }
    if (got != want) {
      std::printf("  row %zu differs: device %zu entries, cpu %zu\n", i, got.size(), want.size());
      return false;
    }
    pairs += got.size();
  }
  return true;
}

template <int Dim, class Real>
void compare_steps(const std::string& name, int steps, double tolerance) {
  std::string source;
  const nlohmann::json j = read_scene_json(name, source);
  auto scene = scene_of<Dim, Real>(j);
  Simulation<Dim, Real> cpu(scene.solver, scene.particles);
  Simulation<Dim, Real> gpu(scene.solver, scene.particles);
  gpu.use_backend(g_device);
  Stopwatch sw;
  for (int s = 0; s < steps; ++s) cpu.step();
  const double cpu_s = sw.seconds();
  sw.reset();
  for (int s = 0; s < steps; ++s) gpu.step();
  const double gpu_s = sw.seconds();
  const auto& a = cpu.particles();
  const auto& b = gpu.particles();
  if (a.size() != b.size()) {  // emitters and sinks: a particle crossed a sink or buffer boundary apart
    verdict(false, name + ": " + std::to_string(a.size()) + " particles on the cpu, " +
                       std::to_string(b.size()) + " on the gpu after " + std::to_string(steps) + " steps");
    return;
  }
  double extent = 0, worst = 0;
  std::size_t same = 0, total = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < Dim; ++k) {
      extent = std::max(extent, std::abs(double(a.x[i][k])));
      worst = std::max(worst, std::abs(double(a.x[i][k]) - double(b.x[i][k])));
      same += std::memcmp(&a.x[i][k], &b.x[i][k], sizeof(Real)) == 0;
      ++total;
    }
  const double rel = worst / std::max(extent, 1e-300);
  std::printf(
      "  %s: %zu particles, %d steps: cpu %.2f s, gpu %.2f s; t = %.9g / %.9g; position components "
      "bit-identical %zu of %zu; max |dx| / extent = %.3g\n",
      name.c_str(), a.size(), steps, cpu_s, gpu_s, double(cpu.time()), double(gpu.time()), same, total, rel);
  char within[32];
  std::snprintf(within, sizeof within, "%g", tolerance);
  verdict(rel <= tolerance,
          name + " " + std::to_string(steps) + " steps: positions within " + within + " of the extent");
  std::uint64_t pairs = 0;
  const bool rows_ok = rows_equal(scene.solver, b, pairs);  // before the message reads pairs
  verdict(rows_ok && pairs > 0, name + ": device rows equal the CPU search's on the final state (" +
                                    std::to_string(pairs) + " pairs)");
}

struct Timing {
  double step_ms = 0, neighbors_ms = 0, dt = 0, bytes_per_particle = 0;
  std::size_t fluid = 0, total = 0, pairs = 0;  // pairs: the device rows' entries (fluid and wall rows)
};

template <int Dim, class Real>
Timing time_case(const nlohmann::json& j, Backend backend, int warmup, int steps) {
  auto scene = scene_of<Dim, Real>(j);
  const std::size_t mem0 = cuda_memory_in_use();
  Simulation<Dim, Real> sim(scene.solver, std::move(scene.particles));
  sim.use_backend(backend);
  for (int s = 0; s < warmup; ++s) sim.step();
  const StepTimings t0 = sim.timings();
  const Real time0 = sim.time();
  Stopwatch sw;
  for (int s = 0; s < steps; ++s) sim.step();
  Timing r;
  r.step_ms = sw.ms() / steps;
  r.neighbors_ms = (sim.timings().neighbors - t0.neighbors) / steps;
  r.dt = double(sim.time() - time0) / steps;
  r.fluid = sim.fluid_count();
  r.total = sim.particles().size();
  if (backend == Backend::Cuda) r.bytes_per_particle = double(cuda_memory_in_use() - mem0) / double(r.total);
  if (backend != Backend::Cpu) {  // the rows of the final state, counted after the timing
    sim.use_backend(Backend::Cpu);
    auto dev = make_device(scene.solver);
    dev->upload(sim.particles());
    const DeviceRows d = dev->neighbor_rows();
    r.pairs = d.rows.size() + d.wall_rows.size();
  }
  return r;
}

void bench(const std::vector<std::size_t>& sizes, int warmup, int steps, std::size_t cpu_size) {
  std::string source;
  const nlohmann::json base = read_scene_json("dam-break-3d", source);
  double volume = 0;
  for (const auto& b : base.at("fluids")) {
    double e = 1;
    for (std::size_t a = 0; a < 3; ++a)
      e *= b.at("max").at(a).get<double>() - b.at("min").at(a).get<double>();
    volume += e;
  }
  std::printf("\n== bench: dam-break-3d rescaled (spacing s for the fluid count, support 2 s), float ==\n");
  std::printf("  %-7s %10s %10s %10s %10s %8s %14s %14s %10s %12s\n", "backend", "fluid", "total", "step ms",
              "search ms", "nbr%", "Mfluid-steps/s", "wall s/sim s", "B/particle", "Gpairs/s");
  for (const std::size_t n : sizes) {
    nlohmann::json j = base;
    const double spacing = std::cbrt(volume / double(n));
    j["spacing"] = spacing;
    j["solver"]["support"] = 2 * spacing;
    j["precision"] = "float";
    for (const Backend b : {g_device, Backend::Cpu}) {
      if (b == Backend::Cpu && n != cpu_size) continue;
      const Timing t =
          time_case<3, float>(j, b, b == Backend::Cpu ? 1 : warmup, b == Backend::Cpu ? 3 : steps);
      std::printf("  %-7s %10zu %10zu %10.3f %10.3f %7.1f%% %14.2f %14.2f %10.0f %12.2f\n",
                  std::string(backend_name(b)).c_str(), t.fluid, t.total, t.step_ms, t.neighbors_ms,
                  100 * t.neighbors_ms / t.step_ms, double(t.fluid) / (t.step_ms * 1e3),
                  t.step_ms / 1e3 / t.dt, t.bytes_per_particle, double(t.pairs) / (t.neighbors_ms * 1e6));
      std::fflush(stdout);
    }
  }
}

// DFSPH's headline measure (issue 12): the built-in dam-break-3d-dfsph (SPlisHSPlasH's DamBreakModel size,
// float) run from rest for a stretch of simulated time on each backend, capped in wall time: wall seconds
// per simulated second, steps, and the mean step; on the device also without the scene's reordering (every
// 25 steps, a round trip of every field on the device).
void bench_dfsph(double until, double wall_cap) {
  std::string source;
  const nlohmann::json scene_json = read_scene_json("dam-break-3d-dfsph", source);
  std::printf("\n== bench: dam-break-3d-dfsph from rest to t = %g s (wall cap %g s) ==\n", until, wall_cap);
  std::printf("  %-7s %8s %10s %10s %8s %12s %10s %14s\n", "backend", "reorder", "fluid", "total", "steps",
              "sim s", "ms/step", "wall s/sim s");
  for (const auto& [b, reorder] :
       {std::pair{g_device, true}, std::pair{g_device, false}, std::pair{Backend::Cpu, true}}) {
    nlohmann::json j = scene_json;
    if (!reorder) j["neighbors"]["reorder_every"] = 0;
    auto scene = scene_of<3, float>(j);
    Simulation<3, float> sim(scene.solver, std::move(scene.particles));
    sim.use_backend(b);
    Stopwatch sw;
    int steps = 0;
    while (double(sim.time()) < until && sw.seconds() < wall_cap) {
      sim.step();
      ++steps;
    }
    const double wall = sw.seconds();
    std::printf("  %-7s %8d %10zu %10zu %8d %12.4f %10.2f %14.2f\n", std::string(backend_name(b)).c_str(),
                scene.solver.reorder_every, sim.fluid_count(), sim.particles().size(), steps,
                double(sim.time()), 1e3 * wall / steps, wall / double(sim.time()));
    std::fflush(stdout);
  }
}

// One case of the check: an exception fails that case and the next one still runs (after a sticky CUDA
// error the rest fail too, each with its own message).
template <class F>
void guarded(const std::string& what, F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    verdict(false, what + ": exception: " + e.what());
  }
}

// The backends side by side on the built-in scenes (positions after N steps, rows on the final state).
void compare_backends(int steps, int dfsph_steps) {
  std::printf("\n== CPU vs CUDA ==\n");
  // Float: every expression is the CPU's (--fmad=false, IEEE division and sqrt), so the difference
  // comes only from library functions that round differently (pow in some equations of state);
  // 1e-5 of the extent is ~100 float ulps of it.
  guarded("dam-break-3d", [&] { compare_steps<3, float>("dam-break-3d", steps, 1e-5); });
  // Double: the 1e-9.
  for (const char* name : {"dam-break-2d", "hydrostatic-tank",  // continuity density + Fourtakas
                           "two-phase",                         // the paper's model, leap-frog
                           "dam-break-2d-dfsph",                // DFSPH: solves, warm starts, sums
                           "dam-break-gate",                    // a moving wall (the gate)
                           "channel-inflow",                    // emitter and sink: counts change
                           "floating-box"})                     // a floating body
    guarded(name, [&] { compare_steps<2, double>(name, steps, 1e-9); });
  // DFSPH in 3D, float, at SPlisHSPlasH's DamBreakModel size (~3 * 10^5 particles with the walls).
  guarded("dam-break-3d-dfsph", [&] { compare_steps<3, float>("dam-break-3d-dfsph", dfsph_steps, 1e-5); });
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {100000, 1000000};
  int steps = 200, bench_steps = 20;
  double dfsph_until = 0, dfsph_wall = 60;
  int dfsph_steps = 50;
  bool compare = true;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--sizes" && k + 1 < argc) {
      sizes.clear();
      for (const char* s = argv[++k]; *s;) {
        char* end = nullptr;
        sizes.push_back(std::strtoull(s, &end, 10));
        s = *end == ',' ? end + 1 : end;
      }
    } else if (a == "--steps" && k + 1 < argc) {
      steps = std::atoi(argv[++k]);
    } else if (a == "--bench-steps" && k + 1 < argc) {
      bench_steps = std::atoi(argv[++k]);
    } else if (a == "--dfsph-steps" && k + 1 < argc) {
      dfsph_steps = std::atoi(argv[++k]);
    } else if (a == "--bench-only") {
      compare = false;
    } else if (a == "--host-device") {
      g_device = Backend::HostDevice;
    } else if (a == "--dfsph-until" && k + 1 < argc) {
      dfsph_until = std::atof(argv[++k]);
    } else if (a == "--dfsph-wall" && k + 1 < argc) {
      dfsph_wall = std::atof(argv[++k]);
    } else {
      std::fprintf(stderr,
                   "usage: cellsph_gpu_check [--sizes N,N] [--steps N] [--bench-steps N] [--dfsph-steps N] "
                   "[--dfsph-until T] [--dfsph-wall S] [--host-device] [--bench-only]\n");
      return 2;
    }
  }
  try {
    const CudaDeviceReport dev = cuda_device_report();
    std::printf("device: %s\nOpenMP threads: %d\n", dev.text.c_str(), omp_get_max_threads());
    if (!dev.ok && g_device == Backend::Cuda) return 2;
    if (compare) compare_backends(steps, dfsph_steps);
    guarded("bench", [&] { bench(sizes, 3, bench_steps, sizes.front()); });
    if (dfsph_until > 0) guarded("bench dfsph", [&] { bench_dfsph(dfsph_until, dfsph_wall); });
  } catch (const std::exception& e) {
    std::printf("FAIL exception: %s\n", e.what());
    return 1;
  }
  std::printf("\n%s: %d failure(s)\n", g_failures ? "FAILED" : "ALL PASSED", g_failures);
  return g_failures ? 1 : 0;
}
