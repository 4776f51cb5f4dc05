#pragma once
// Smoothing kernels as small value types: each holds its support length h and the constants that
// depend on it, so kernels are passed by value and two simulations never share state.
//
// Every kernel here has compact support h (W = 0 for r > h) and integrates to 1 over its support in
// the dimension it is instantiated for. Derivatives are written as radial functions:
//   gradW(r) = W'(r) r/|r|,   laplacian(r) = W''(r) + (Dim - 1) W'(r) / r.
// gradW_factor(r) is the scalar W'(|r|)/|r| of that gradient, computed as gradW computes it: within the
// support gradW(r) and r * gradW_factor(r) have the same bits (beyond it both are zero, up to the sign of
// zero), so a caller that keeps r may store one scalar per pair instead of a vector (models/dfsph.hpp).
//
// Notes on the paper's printed constants (checked by the normalisation and finite-difference tests):
//  * eq. 10 prints the viscosity kernel with 15/(2 pi h^6); Mueller et al. (2003) use 15/(2 pi h^3),
//    which is what integrates to 1 and what gives the eq. 18 Laplacian 45/(pi h^6)(h - r).
//  * eq. 18 prints the poly6 Laplacian with 315/(64 pi h^9); differentiating eq. 10 gives 945/(32 pi h^9)
//    (a factor 6), which is also the constant the CUDA write-up uses.
//  * In 2D, Mueller's viscosity polynomial has a Laplacian with an r^-3 singularity. We use the 2D kernel
//    defined by the same design rule as the 3D one (Laplacian linear in r, W and W' zero at h), which
//    works out to W = 40/(pi h^5) [h r^2/4 - r^3/9 - 5h^3/36 + (h^3/6) ln(h/r)], Laplacian 40/(pi h^5)(h-r).
#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

enum class KernelKind { Poly6, Spiky, Viscosity, CubicSpline, WendlandC2 };

std::string_view kernel_name(KernelKind k);
std::optional<KernelKind> parse_kernel(std::string_view name);

namespace detail {
template <class Real>
CELLSPH_HD inline Real ipow(Real x, int n) {
  Real r = 1;
  for (int k = 0; k < n; ++k) r *= x;
  return r;
}
template <class Real>
inline constexpr Real kPi = std::numbers::pi_v<Real>;

// r/|r| * dw, with dw = W'(|r|); zero at r = 0 (every kernel here is smooth or symmetric there).
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> radial(const Vec<Dim, Real>& rv, Real r, Real dw) {
  if (r <= Real(0)) return Vec<Dim, Real>{};
  return rv * (dw / r);
}
}  // namespace detail

// W(|r|) and W'(|r|)/|r| of one pair (kernel_value_and_factor).
template <class Real>
struct KernelValueAndFactor {
  Real value, factor;
};

// Poly6 (Mueller 2003; paper eq. 10, 18): density and colour field.
template <int Dim, class Real>
struct Poly6Kernel {
  Real h{}, h2{}, sigma{};
  Poly6Kernel() = default;
  CELLSPH_HD explicit Poly6Kernel(Real support) : h(support), h2(support * support) {
    sigma = Dim == 3 ? Real(315) / (Real(64) * detail::kPi<Real> * detail::ipow(h, 9))
                     : Real(4) / (detail::kPi<Real> * detail::ipow(h, 8));
  }
  // W from the squared distance: no square root in the density loop.
  CELLSPH_HD Real W2(Real r2) const {
    if (r2 > h2) return 0;
    const Real d = h2 - r2;
    return sigma * d * d * d;
  }
  CELLSPH_HD Real W(Real r) const { return W2(r * r); }
  CELLSPH_HD Real dW(Real r) const {
    if (r > h) return 0;
    const Real d = h2 - r * r;
    return Real(-6) * sigma * r * d * d;
  }
  CELLSPH_HD Vec<Dim, Real> gradW(const Vec<Dim, Real>& rv) const {
    const Real r2 = norm2(rv);
    if (r2 > h2) return Vec<Dim, Real>{};
    const Real d = h2 - r2;
    return rv * (Real(-6) * sigma * d * d);
  }
  CELLSPH_HD Real gradW_factor(const Vec<Dim, Real>& rv) const {
    const Real r2 = norm2(rv);
    if (r2 > h2) return 0;
    const Real d = h2 - r2;
    return Real(-6) * sigma * d * d;
  }
  CELLSPH_HD Real laplacian(Real r) const {
    if (r > h) return 0;
    const Real r2 = r * r, d = h2 - r2;
    return sigma * d * (Real(24) * r2 - Real(6 * Dim) * d);
  }
};

// Spiky (Desbrun 1996, Mueller 2003; eq. 10, 18): pressure gradient that does not vanish at r -> 0.
template <int Dim, class Real>
struct SpikyKernel {
  Real h{}, sigma{};
  SpikyKernel() = default;
  CELLSPH_HD explicit SpikyKernel(Real support) : h(support) {
    sigma = Dim == 3 ? Real(15) / (detail::kPi<Real> * detail::ipow(h, 6))
                     : Real(10) / (detail::kPi<Real> * detail::ipow(h, 5));
  }
  CELLSPH_HD Real W(Real r) const {
    if (r > h) return 0;
    const Real d = h - r;
    return sigma * d * d * d;
  }
  CELLSPH_HD Real W2(Real r2) const { return W(std::sqrt(r2)); }
  CELLSPH_HD Real dW(Real r) const {
    if (r > h) return 0;
    const Real d = h - r;
    return Real(-3) * sigma * d * d;
  }
  CELLSPH_HD Vec<Dim, Real> gradW(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return detail::radial(rv, r, dW(r));
  }
  CELLSPH_HD Real gradW_factor(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return r > Real(0) ? dW(r) / r : Real(0);
  }
  // Singular at r = 0 (a cusp); defined for r > 0 only.
  CELLSPH_HD Real laplacian(Real r) const {
    if (r > h) return 0;
    const Real d = h - r;
    return Real(6) * sigma * d - Real(3 * (Dim - 1)) * sigma * d * d / r;
  }
};

// Viscosity kernel (Mueller 2003; eq. 10, 18): positive Laplacian, so viscosity only damps.
template <int Dim, class Real>
struct ViscosityKernel {
  Real h{}, sigma{}, lap{};
  ViscosityKernel() = default;
  CELLSPH_HD explicit ViscosityKernel(Real support) : h(support) {
    if constexpr (Dim == 3) {
      sigma = Real(15) / (Real(2) * detail::kPi<Real> * detail::ipow(h, 3));
      lap = Real(45) / (detail::kPi<Real> * detail::ipow(h, 6));
    } else {
      sigma = Real(40) / (detail::kPi<Real> * detail::ipow(h, 5));
      lap = sigma;
    }
  }
  // Singular (integrably) at r = 0, as in the paper.
  CELLSPH_HD Real W(Real r) const {
    if (r > h) return 0;
    if constexpr (Dim == 3) {
      const Real q = r / h;
      return sigma * (-q * q * q / 2 + q * q + Real(1) / (Real(2) * q) - 1);
    } else {
      const Real h3 = h * h * h;
      return sigma * (h * r * r / 4 - r * r * r / 9 - Real(5) * h3 / 36 + h3 / 6 * std::log(h / r));
    }
  }
  CELLSPH_HD Real W2(Real r2) const { return W(std::sqrt(r2)); }
  CELLSPH_HD Real dW(Real r) const {
    if (r > h) return 0;
    if constexpr (Dim == 3) {
      return sigma *
             (Real(-3) * r * r / (Real(2) * h * h * h) + Real(2) * r / (h * h) - h / (Real(2) * r * r));
    } else {
      return sigma * (h * r / 2 - r * r / 3 - h * h * h / (Real(6) * r));
    }
  }
  CELLSPH_HD Vec<Dim, Real> gradW(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return detail::radial(rv, r, dW(r));
  }
  CELLSPH_HD Real gradW_factor(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return r > Real(0) ? dW(r) / r : Real(0);
  }
  CELLSPH_HD Real laplacian(Real r) const { return r > h ? Real(0) : lap * (h - r); }
};

// Cubic B-spline (Monaghan 1992) with compact support h (q = r/h), as in Koschier et al. 2020.
template <int Dim, class Real>
struct CubicSplineKernel {
  Real h{}, inv_h{}, sigma{};
  CubicSplineKernel() = default;
  CELLSPH_HD explicit CubicSplineKernel(Real support) : h(support), inv_h(Real(1) / support) {
    sigma = Dim == 3 ? Real(8) / (detail::kPi<Real> * h * h * h)
                     : Real(40) / (Real(7) * detail::kPi<Real> * h * h);
  }
  // The two pieces of W and W': for q = r / h up to 1/2, and in d = 1 - q beyond (W, dW and
  // value_and_factor take them from here).
  CELLSPH_HD Real w_inner(Real q) const { return sigma * (Real(6) * (q * q * q - q * q) + 1); }
  CELLSPH_HD Real w_outer(Real d) const { return sigma * Real(2) * d * d * d; }
  CELLSPH_HD Real dw_inner(Real q) const { return sigma * inv_h * Real(6) * (Real(3) * q * q - Real(2) * q); }
  CELLSPH_HD Real dw_outer(Real d) const { return sigma * inv_h * Real(-6) * d * d; }
  CELLSPH_HD Real W(Real r) const {
    const Real q = r * inv_h;
    if (q > 1) return 0;
    return q <= Real(0.5) ? w_inner(q) : w_outer(1 - q);
  }
  CELLSPH_HD Real W2(Real r2) const { return W(std::sqrt(r2)); }
  CELLSPH_HD Real dW(Real r) const {
    const Real q = r * inv_h;
    if (q > 1) return 0;
    return q <= Real(0.5) ? dw_inner(q) : dw_outer(1 - q);
  }
  CELLSPH_HD Vec<Dim, Real> gradW(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return detail::radial(rv, r, dW(r));
  }
  CELLSPH_HD Real gradW_factor(const Vec<Dim, Real>& rv) const {
    const Real r = norm(rv);
    return r > Real(0) ? dW(r) / r : Real(0);
  }
  // W2(r2) and gradW_factor of a vector of squared length r2, with their bits, from one square root and
  // without a branch a pair would take or not (both pieces are computed, then selected).
  CELLSPH_HD KernelValueAndFactor<Real> value_and_factor(Real r2) const {
    const Real r = std::sqrt(r2);
    const Real q = r * inv_h;
    const Real d = 1 - q;
    const bool inner = q <= Real(0.5), inside = !(q > 1), positive = r > Real(0);
    const Real w = inner ? w_inner(q) : w_outer(d);
    const Real dw = inner ? dw_inner(q) : dw_outer(d);
    const Real f = dw / (positive ? r : Real(1));
    return {inside ? w : Real(0), inside && positive ? f : Real(0)};
  }
  // Finite at r = 0 from the limit W'(r)/r -> -12 sigma / h^2.
  CELLSPH_HD Real laplacian(Real r) const {
    const Real q = r * inv_h;
    if (q > 1) return 0;
    const Real s = sigma * inv_h * inv_h;
    if (q <= Real(0.5)) return s * (Real(6) * (Real(6) * q - 2) + Real(6 * (Dim - 1)) * (Real(3) * q - 2));
    const Real d = 1 - q;
    return s * (Real(12) * d - Real(6 * (Dim - 1)) * d * d / q);
  }
};

// Wendland C2 (Wendland 1995) with compact support h: no pairing instability, positive everywhere.
template <int Dim, class Real>
struct WendlandC2Kernel {
  Real h{}, inv_h{}, sigma{};
  WendlandC2Kernel() = default;
  CELLSPH_HD explicit WendlandC2Kernel(Real support) : h(support), inv_h(Real(1) / support) {
    sigma = Dim == 3 ? Real(21) / (Real(2) * detail::kPi<Real> * h * h * h)
                     : Real(7) / (detail::kPi<Real> * h * h);
  }
  // W and W'(r)/r for q = r / h <= 1 (W, gradW, gradW_factor and value_and_factor take them from here).
  // W'(r)/r = -20 sigma (1-q)^3 / h^2 is regular at r = 0: no division by r.
  CELLSPH_HD Real w_of(Real q) const {
    const Real d = 1 - q, d2 = d * d;
    return sigma * d2 * d2 * (1 + Real(4) * q);
  }
  CELLSPH_HD Real factor_of(Real q) const {
    const Real d = 1 - q;
    return Real(-20) * sigma * inv_h * inv_h * d * d * d;
  }
  CELLSPH_HD Real W(Real r) const {
    const Real q = r * inv_h;
    return q > 1 ? Real(0) : w_of(q);
  }
  CELLSPH_HD Real W2(Real r2) const { return W(std::sqrt(r2)); }
  CELLSPH_HD Real dW(Real r) const {
    const Real q = r * inv_h;
    if (q > 1) return 0;
    const Real d = 1 - q;
    return Real(-20) * sigma * inv_h * q * d * d * d;
  }
  CELLSPH_HD Vec<Dim, Real> gradW(const Vec<Dim, Real>& rv) const {
    const Real q = norm(rv) * inv_h;
    return q > 1 ? Vec<Dim, Real>{} : rv * factor_of(q);
  }
  CELLSPH_HD Real gradW_factor(const Vec<Dim, Real>& rv) const {
    const Real q = norm(rv) * inv_h;
    return q > 1 ? Real(0) : factor_of(q);
  }
  // W2(r2) and gradW_factor with their bits, from one square root (as CubicSplineKernel's).
  CELLSPH_HD KernelValueAndFactor<Real> value_and_factor(Real r2) const {
    const Real q = std::sqrt(r2) * inv_h;
    if (q > 1) return {Real(0), Real(0)};
    return {w_of(q), factor_of(q)};
  }
  CELLSPH_HD Real laplacian(Real r) const {
    const Real q = r * inv_h;
    if (q > 1) return 0;
    const Real d = 1 - q;
    return Real(-20) * sigma * inv_h * inv_h * d * d * ((1 - Real(4) * q) + Real(Dim - 1) * d);
  }
};

// Akinci et al. 2013 cohesion spline C(r): repulsive (negative) below r = h/2, attractive up to h, zero
// beyond. 3D: their normalisation 32 / (pi h^9). 2D (not in the paper): the same polynomial scaled so
// that its integral over the plane equals the 3D one over space (79/336 for every h):
// 25280 / (627 pi h^8).
template <int Dim, class Real>
struct CohesionKernel {
  static_assert(Dim == 2 || Dim == 3);
  Real h, norm;
  explicit CohesionKernel(Real support)
      : h(support),
        norm(Dim == 3 ? Real(32.0 / (std::numbers::pi * std::pow(double(support), 9)))
                      : Real(25280.0 / (627.0 * std::numbers::pi * std::pow(double(support), 8)))) {}
  CELLSPH_HD Real C(Real r) const {
    if (!(r > 0) || r > h) return 0;
    const Real a = (h - r) * (h - r) * (h - r) * r * r * r;
    if (2 * r > h) return norm * a;
    const Real h3 = h * h * h;
    return norm * (2 * a - h3 * h3 / 64);
  }
};

// W(|rv|) and W'(|rv|)/|rv| of one pair, r2 = |rv|^2: the bits of k.W2(r2) and k.gradW_factor(rv), from one
// square root where the kernel has value_and_factor.
template <class Kernel, int Dim, class Real>
CELLSPH_HD inline KernelValueAndFactor<Real> kernel_value_and_factor(const Kernel& k,
                                                                     const Vec<Dim, Real>& rv, Real r2) {
  if constexpr (requires { k.value_and_factor(r2); })
    return k.value_and_factor(r2);
  else
    return {k.W2(r2), k.gradW_factor(rv)};
}

// Calls f(kernel) with the kernel of the given kind: the one run-time switch, taken once per loop, so
// the per-neighbour code is inlined for a concrete kernel type.
template <int Dim, class Real, class F>
decltype(auto) with_kernel(KernelKind kind, Real h, F&& f) {
  switch (kind) {
    case KernelKind::Poly6:
      return f(Poly6Kernel<Dim, Real>(h));
    case KernelKind::Spiky:
      return f(SpikyKernel<Dim, Real>(h));
    case KernelKind::Viscosity:
      return f(ViscosityKernel<Dim, Real>(h));
    case KernelKind::CubicSpline:
      return f(CubicSplineKernel<Dim, Real>(h));
    case KernelKind::WendlandC2:
      break;
  }
  return f(WendlandC2Kernel<Dim, Real>(h));
}

}  // namespace cellsph
