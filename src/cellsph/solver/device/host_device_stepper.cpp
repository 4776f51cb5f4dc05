// The host-emulated device backend (Backend::HostDevice): DeviceStepper over HostDeviceSpace, compiled
// by the host compiler, so the device path (allocations, copies over the field list, the grid, the rows,
// the step's sequence) runs in every build and under ASan/UBSan in CI.
#include <memory>

#include "cellsph/solver/device/device_stepper.hpp"

namespace cellsph {

template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_host_device_stepper(const SolverConfig<Dim, Real>& cfg) {
  return std::make_unique<DeviceStepper<Dim, Real, HostDeviceSpace>>(cfg);
}

template std::unique_ptr<DeviceStepperBase<2, float>> make_host_device_stepper(const SolverConfig<2, float>&);
template std::unique_ptr<DeviceStepperBase<2, double>> make_host_device_stepper(
    const SolverConfig<2, double>&);
template std::unique_ptr<DeviceStepperBase<3, float>> make_host_device_stepper(const SolverConfig<3, float>&);
template std::unique_ptr<DeviceStepperBase<3, double>> make_host_device_stepper(
    const SolverConfig<3, double>&);

}  // namespace cellsph
