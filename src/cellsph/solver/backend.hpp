#pragma once
// The execution backend of a run, chosen once at the top (`--backend`, scene key solver.backend,
// Python's Simulation(backend=...)): the CPU (OpenMP over the passes) or a CUDA device (the same passes
// as kernels, solver/device/). This header includes nothing of CUDA: a build without it has the same
// interface, and asking it for the CUDA backend is an InputError.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace cellsph {

enum class Backend {
  Cpu,
  Cuda,
  // Host memory used through the device API (separate allocations, explicit copies, the device step):
  // the CUDA backend's bookkeeping without a GPU, for tests. Not offered to users.
  HostDevice,
};

std::string_view backend_name(Backend b);
// "cpu" or "cuda" ("host-device" too, for tests).
std::optional<Backend> parse_backend(std::string_view name);

// True when this build holds the CUDA backend (configured with CELLSPH_CUDA and nvcc).
bool cuda_built();

// What a CUDA run would use, in one line: the device (name, memory, compute capability), or why there is
// none (the CUDA runtime's message), or that the build has no CUDA backend. ok: a device can be used.
struct CudaDeviceReport {
  bool ok = false;
  std::string text;
};
CudaDeviceReport cuda_device_report();
// Bytes of device memory in use on device 0 (total - free), or 0 without a device (benchmarks: bytes per
// particle).
std::size_t cuda_memory_in_use();

// Throws when `b` cannot run here: InputError (exit 2) naming `where` (the option or key) when this build
// lacks the backend; std::runtime_error-derived CudaUnavailable when it has it but finds no usable
// device or driver (one line with the CUDA runtime's message). Does nothing for the CPU.
void require_backend(Backend b, std::string_view where);

}  // namespace cellsph
