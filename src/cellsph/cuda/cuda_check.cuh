#pragma once
// Every CUDA runtime call of cellsph goes through CELLSPH_CUDA_CHECK: a failure throws DeviceError naming
// the call, the file, the line and the runtime's message. Seen only by nvcc (cuda/*.cu).
#include <cuda_runtime.h>

#include <string>

#include "cellsph/solver/device/memory_space.hpp"

namespace cellsph::cuda_detail {

[[noreturn]] inline void cuda_failed(cudaError_t err, const char* call, const char* file, int line) {
  throw DeviceError(std::string("CUDA call ") + call + " failed at " + file + ":" + std::to_string(line) +
                    ": " + cudaGetErrorName(err) + ": " + cudaGetErrorString(err));
}

}  // namespace cellsph::cuda_detail

#define CELLSPH_CUDA_CHECK(call)                                                         \
  do {                                                                                   \
    const cudaError_t cellsph_cuda_err_ = (call);                                        \
    if (cellsph_cuda_err_ != cudaSuccess)                                                \
      ::cellsph::cuda_detail::cuda_failed(cellsph_cuda_err_, #call, __FILE__, __LINE__); \
  } while (0)
