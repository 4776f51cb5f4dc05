#include "cellsph/solver/backend.hpp"

#include <string>

#include "cellsph/core/error.hpp"

namespace cellsph {

std::string_view backend_name(Backend b) {
  switch (b) {
    case Backend::Cpu:
      return "cpu";
    case Backend::Cuda:
      return "cuda";
    case Backend::HostDevice:
      return "host-device";
  }
  return "?";
}

std::optional<Backend> parse_backend(std::string_view name) {
  for (const Backend b : {Backend::Cpu, Backend::Cuda, Backend::HostDevice})
    if (name == backend_name(b)) return b;
  return std::nullopt;
}

void require_backend(Backend b, std::string_view where) {
  if (b != Backend::Cuda) return;
  if (!cuda_built())
    throw InputError(std::string(where) +
                     ": this build has no CUDA backend (configure with -DCELLSPH_CUDA=ON and nvcc); use "
                     "--backend cpu");
  const CudaDeviceReport r = cuda_device_report();
  if (!r.ok)
    throw InputError(std::string(where) + ": no usable CUDA device: " + r.text + "; use --backend cpu");
}

}  // namespace cellsph
