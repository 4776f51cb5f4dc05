// The CUDA backend's step: DeviceStepper (solver/device/device_stepper.hpp) over CudaSpace, whose passes
// the overloads of cuda_driver.cuh launch as kernels. The (Dim, Real) instantiations of one dimension per
// translation unit (cuda_steppers_2d.cu, cuda_steppers_3d.cu): two files that nvcc compiles in parallel on
// CI's 2 cores.
//
// NOT RUN YET: compiled in CI (no GPU there); scripts/gpu_check.sh runs it when a GPU is lent.
#include <memory>

// The CUDA overloads first, so that the passes' run_pass calls in the model files find them.
#include "cellsph/cuda/cuda_driver.cuh"
#include "cellsph/solver/device/device_stepper.hpp"

namespace cellsph {

template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_cuda_stepper(const SolverConfig<Dim, Real>& cfg) {
  return std::make_unique<DeviceStepper<Dim, Real, CudaSpace>>(cfg);
}

template std::unique_ptr<DeviceStepperBase<2, float>> make_cuda_stepper(const SolverConfig<2, float>&);
template std::unique_ptr<DeviceStepperBase<2, double>> make_cuda_stepper(const SolverConfig<2, double>&);

}  // namespace cellsph
