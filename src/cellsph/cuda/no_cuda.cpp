// The CUDA entry points of a build without the CUDA backend (CELLSPH_CUDA off or no nvcc); a CUDA build
// defines them in cuda/*.cu instead.
#ifndef CELLSPH_HAVE_CUDA
#include <memory>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/backend.hpp"
#include "cellsph/solver/device/device_stepper_base.hpp"

namespace cellsph {

bool cuda_built() {
  return false;
}

CudaDeviceReport cuda_device_report() {
  return {false, "none: this build has no CUDA backend (configure with -DCELLSPH_CUDA=ON and nvcc)"};
}

std::size_t cuda_memory_in_use() {
  return 0;
}

template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_cuda_stepper(const SolverConfig<Dim, Real>&) {
  throw InputError("this build has no CUDA backend (configure with -DCELLSPH_CUDA=ON and nvcc)");
}

template std::unique_ptr<DeviceStepperBase<2, float>> make_cuda_stepper(const SolverConfig<2, float>&);
template std::unique_ptr<DeviceStepperBase<2, double>> make_cuda_stepper(const SolverConfig<2, double>&);
template std::unique_ptr<DeviceStepperBase<3, float>> make_cuda_stepper(const SolverConfig<3, float>&);
template std::unique_ptr<DeviceStepperBase<3, double>> make_cuda_stepper(const SolverConfig<3, double>&);

}  // namespace cellsph
#endif
