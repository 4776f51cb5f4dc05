// The host-emulated device's entry point in the fuzz build: the readers under test never step on it, and
// compiling the real one (solver/device/host_device_stepper.cpp: every model's device passes, four times)
// was half of the fuzz build's time (189 of 360 s cold in CI). A scene or checkpoint asking for it gets
// an InputError, which the harnesses take as a reader's refusal.
#include <memory>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/device/device_stepper_base.hpp"

namespace cellsph {

template <int Dim, class Real>
std::unique_ptr<DeviceStepperBase<Dim, Real>> make_host_device_stepper(const SolverConfig<Dim, Real>&) {
  throw InputError("the fuzz build has no host-emulated device");
}

template std::unique_ptr<DeviceStepperBase<2, float>> make_host_device_stepper(const SolverConfig<2, float>&);
template std::unique_ptr<DeviceStepperBase<2, double>> make_host_device_stepper(
    const SolverConfig<2, double>&);
template std::unique_ptr<DeviceStepperBase<3, float>> make_host_device_stepper(const SolverConfig<3, float>&);
template std::unique_ptr<DeviceStepperBase<3, double>> make_host_device_stepper(
    const SolverConfig<3, double>&);

}  // namespace cellsph
