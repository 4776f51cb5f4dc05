// The CUDA backend's runtime part: the build/device report of `cellsph doctor` and --backend cuda, and
// the CudaSpace memory functions (solver/device/memory_space.hpp). Every call is checked
// (cuda_check.cuh).
//
// NOT RUN YET: this machine and CI have no GPU; this file is compiled in CI, and scripts/gpu_check.sh
// runs it on a GPU when one is lent (docs/gpu.md).
#include <cuda_runtime.h>

#include <cstdio>
#include <string>

#include "cellsph/cuda/cuda_check.cuh"
#include "cellsph/solver/backend.hpp"
#include "cellsph/solver/device/memory_space.hpp"

namespace cellsph {

bool cuda_built() {
  return true;
}

CudaDeviceReport cuda_device_report() {
  int runtime = 0, driver = 0;
  cudaRuntimeGetVersion(&runtime);
  const cudaError_t derr = cudaDriverGetVersion(&driver);
  int count = 0;
  const cudaError_t err = cudaGetDeviceCount(&count);
  if (err != cudaSuccess) {
    cudaGetLastError();  // clear it
    return {false, std::string("none: cudaGetDeviceCount: ") + cudaGetErrorString(err) + " (CUDA runtime " +
                       std::to_string(runtime / 1000) + "." + std::to_string(runtime % 1000 / 10) +
                       (derr == cudaSuccess && driver == 0 ? ", no CUDA driver installed)" : ")")};
  }
  if (count == 0) return {false, "none: cudaGetDeviceCount: the CUDA driver reports 0 devices"};
  cudaDeviceProp prop{};
  const cudaError_t perr = cudaGetDeviceProperties(&prop, 0);
  if (perr != cudaSuccess)
    return {false, std::string("none: cudaGetDeviceProperties: ") + cudaGetErrorString(perr)};
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s, %.1f GiB, compute capability %d.%d (device 0 of %d; driver %d.%d, runtime %d.%d)",
                prop.name, double(prop.totalGlobalMem) / double(1u << 30), prop.major, prop.minor, count,
                driver / 1000, driver % 1000 / 10, runtime / 1000, runtime % 1000 / 10);
  return {true, buf};
}

std::size_t cuda_memory_in_use() {
  std::size_t free = 0, total = 0;
  if (cudaMemGetInfo(&free, &total) != cudaSuccess) {
    cudaGetLastError();
    return 0;
  }
  return total - free;
}

void* CudaSpace::allocate(std::size_t bytes) {
  void* p = nullptr;
  if (bytes == 0) return nullptr;
  CELLSPH_CUDA_CHECK(cudaMalloc(&p, bytes));
  return p;
}
void CudaSpace::release(void* p) noexcept {
  if (p) cudaFree(p);  // in a destructor: an error here (a lost context) cannot be reported
}
void CudaSpace::to_device(void* dst, const void* src, std::size_t bytes) {
  CELLSPH_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyHostToDevice));
}
void CudaSpace::to_host(void* dst, const void* src, std::size_t bytes) {
  CELLSPH_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToHost));
}
void CudaSpace::on_device(void* dst, const void* src, std::size_t bytes) {
  CELLSPH_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToDevice));
}
void CudaSpace::zero(void* dst, std::size_t bytes) {
  CELLSPH_CUDA_CHECK(cudaMemset(dst, 0, bytes));
}

}  // namespace cellsph
