// `cellsph doctor`: what this build can do on this machine, for a bug report or before a long run: the
// backends, the device (or why none), OpenMP threads, the CPU's vector extensions the search uses, and
// the versions of the compiler and the main libraries.
#include <omp.h>

#include <cstdio>
#include <string>
#include <thread>

#include <nanoflann.hpp>
#include <nlohmann/json.hpp>

#include "cellsph/distributed/communicator.hpp"
#include "cellsph/neighbors/cell_index_simd.hpp"
#include "cellsph/render/image.hpp"
#include "cellsph/solver/backend.hpp"
#include "cellsph/surface/surface.hpp"
#include "commands.hpp"

namespace cellsph::app {
namespace {

std::string nanoflann_version() {
  const int v = NANOFLANN_VERSION;  // 0xMmp
  return std::to_string(v >> 8) + "." + std::to_string((v >> 4) & 0xf) + "." + std::to_string(v & 0xf);
}

int doctor() {
  if (distributed::world().rank() != 0) return 0;  // under mpirun: one report, rank 0's
  std::printf("cellsph 0.1.0, %s build%s\n",
#ifdef NDEBUG
              "optimised",
#else
              "debug",
#endif
#ifdef CELLSPH_NATIVE_BUILD
              " for this machine's CPU (CELLSPH_NATIVE: -march=native)"
#else
              " for any x86-64 CPU (AVX2 chosen at run time)"
#endif
  );
  if (cuda_built())
    std::printf("backends:     cpu (OpenMP), cuda (--backend cuda; docs/gpu.md)\n");
  else
    std::printf(
        "backends:     cpu (OpenMP); cuda not in this build (configure with -DCELLSPH_CUDA=ON and nvcc)\n");
  std::printf("device:       %s\n", cuda_device_report().text.c_str());
  std::printf(
      "threads:      %d OpenMP threads by default (OMP_NUM_THREADS or --threads to change), %u "
      "hardware threads\n",
      omp_get_max_threads(), std::thread::hardware_concurrency());
  std::printf(
      "cpu:          AVX2 %s; Cell Indexing's inner loops run %s (8 candidates at a time with avx2, 4 with "
      "sse2; CELLSPH_SIMD=sse2 or scalar chooses a narrower one)\n",
      best_simd_path() == SimdPath::Avx2 ? "yes" : "no", simd_path_name(simd_path()));
  const auto world = distributed::world();
  if (!distributed::built_with_mpi())
    std::printf("mpi:          not in this build (Debian's libopenmpi-dev and -DCELLSPH_MPI=ON)\n");
  else if (distributed::launched_by_mpi_launcher())
    std::printf("mpi:          %s; %d ranks (this is rank %d)\n", distributed::mpi_library_version().c_str(),
                world.size(), world.rank());
  else
    std::printf("mpi:          %s; 1 process (not started by mpirun)\n",
                distributed::mpi_library_version().c_str());
  std::printf("compiler:     %s, C++ %ld, OpenMP %d\n",
#if defined(__clang__)
              "clang " __clang_version__,
#elif defined(__GNUC__)
              "g++ " __VERSION__,
#else
              "unknown",
#endif
              static_cast<long>(__cplusplus), _OPENMP);
  std::printf("libraries:    nlohmann-json %d.%d.%d, CLI11 %s, nanoflann %s, OpenVDB %s, libpng %s\n",
              NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH,
              CLI11_VERSION, nanoflann_version().c_str(), openvdb_version().c_str(),
              libpng_version().c_str());
  return 0;
}

}  // namespace

void register_doctor(CLI::App& app, int& result) {
  auto* sub =
      app.add_subcommand("doctor", "Print this build's backends, threads, CPU features and library versions");
  sub->callback([&result] { result = doctor(); });
}

}  // namespace cellsph::app
