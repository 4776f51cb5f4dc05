#pragma once
// Equations of state: pressure from density (paper eq. 7; the write-up's three state equations).
#include <cmath>
#include <optional>
#include <string_view>

#include "cellsph/core/hd.hpp"

namespace cellsph {

enum class EosKind {
  Tait,     // paper eq. 7: k ((rho/rho0)^gamma - 1)
  Linear,   // write-up state equation 0 and the paper's footnote 7: k (rho - rho0)
  Ratio,    // write-up state equation 1: k (rho/rho0 - 1)
  Seventh,  // write-up state equation 2: k ((rho/rho0)^7 - 1)
};

std::string_view eos_name(EosKind k);
std::optional<EosKind> parse_eos(std::string_view name);

template <class Real>
struct EquationOfState {
  EosKind kind = EosKind::Tait;
  Real stiffness = 1000;  // k [Pa] (k [Pa m^3/kg] for Linear)
  Real gamma = 7;         // Tait exponent (Tait only)
  // The write-up keeps pressure non-negative, so that the density deficit at a free surface does not
  // pull particles together (tensile instability); the paper does not clamp.
  bool clamp_negative = false;

  CELLSPH_HD Real pressure(Real rho, Real rho0) const {
    Real p = 0;
    switch (kind) {
      case EosKind::Tait:
        p = stiffness * (std::pow(rho / rho0, gamma) - 1);
        break;
      case EosKind::Linear:
        p = stiffness * (rho - rho0);
        break;
      case EosKind::Ratio:
        p = stiffness * (rho / rho0 - 1);
        break;
      case EosKind::Seventh: {
        const Real q = rho / rho0, q2 = q * q, q3 = q2 * q;
        p = stiffness * (q3 * q3 * q - 1);
        break;
      }
    }
    return clamp_negative && p < 0 ? Real(0) : p;
  }

  // The inverse of pressure() without clamping: the density at which the state equation gives p (Adami et
  // al. 2012 give wall particles the density of their extrapolated pressure). Pressures below the
  // value at rho0 / 2 are taken as that value: further down Tait's and the ratio's inverse run to a
  // zero density, where p / rho^2 of a wall particle would be unbounded.
  CELLSPH_HD Real density(Real p, Real rho0) const {
    EquationOfState<Real> raw = *this;
    raw.clamp_negative = false;
    const Real p_min = raw.pressure(rho0 / 2, rho0);
    if (!(p > p_min)) return rho0 / 2;
    switch (kind) {
      case EosKind::Tait:
        return rho0 * std::pow(1 + p / stiffness, 1 / gamma);
      case EosKind::Linear:
        return rho0 + p / stiffness;
      case EosKind::Ratio:
        return rho0 * (1 + p / stiffness);
      case EosKind::Seventh:
        return rho0 * std::pow(1 + p / stiffness, Real(1) / 7);
    }
    return rho0;
  }

  // Speed of sound c = sqrt(dp/drho) at rest density, for the Courant condition (eq. 12).
  CELLSPH_HD Real sound_speed(Real rho0) const {
    switch (kind) {
      case EosKind::Tait:
        return std::sqrt(stiffness * gamma / rho0);
      case EosKind::Linear:
        return std::sqrt(stiffness);
      case EosKind::Ratio:
        return std::sqrt(stiffness / rho0);
      case EosKind::Seventh:
        return std::sqrt(Real(7) * stiffness / rho0);
    }
    return 0;
  }

  // The stiffness whose sound_speed(rho0) is c: sound_speed's inverse, for the stiffness a scene derives
  // from its height (scene/sound_speed_default.cpp).
  CELLSPH_HD Real stiffness_for_sound_speed(Real c, Real rho0) const {
    switch (kind) {
      case EosKind::Tait:
        return c * c * rho0 / gamma;
      case EosKind::Linear:
        return c * c;
      case EosKind::Ratio:
        return c * c * rho0;
      case EosKind::Seventh:
        return c * c * rho0 / Real(7);
    }
    return 0;
  }
};

}  // namespace cellsph
