#include "cellsph/physics/eos.hpp"

namespace cellsph {

std::string_view eos_name(EosKind k) {
  switch (k) {
    case EosKind::Tait:
      return "tait";
    case EosKind::Linear:
      return "linear";
    case EosKind::Ratio:
      return "ratio";
    case EosKind::Seventh:
      return "seventh";
  }
  return "?";
}

std::optional<EosKind> parse_eos(std::string_view name) {
  for (EosKind k : {EosKind::Tait, EosKind::Linear, EosKind::Ratio, EosKind::Seventh})
    if (eos_name(k) == name) return k;
  return std::nullopt;
}

}  // namespace cellsph
