#include "cellsph/physics/kernels.hpp"

namespace cellsph {

std::string_view kernel_name(KernelKind k) {
  switch (k) {
    case KernelKind::Poly6:
      return "poly6";
    case KernelKind::Spiky:
      return "spiky";
    case KernelKind::Viscosity:
      return "viscosity";
    case KernelKind::CubicSpline:
      return "cubic";
    case KernelKind::WendlandC2:
      return "wendland";
  }
  return "?";
}

std::optional<KernelKind> parse_kernel(std::string_view name) {
  for (KernelKind k : {KernelKind::Poly6, KernelKind::Spiky, KernelKind::Viscosity, KernelKind::CubicSpline,
                       KernelKind::WendlandC2})
    if (kernel_name(k) == name) return k;
  return std::nullopt;
}

}  // namespace cellsph
