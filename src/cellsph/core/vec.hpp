#pragma once
// Small fixed-size vector, templated on dimension and scalar (one type for 2D and 3D).
#include <cmath>
#include <cstddef>

#include "cellsph/core/hd.hpp"

namespace cellsph {

template <int Dim, class Real>
struct Vec {
  static_assert(Dim == 2 || Dim == 3, "cellsph supports 2D and 3D");
  Real c[Dim]{};

  static constexpr int dim = Dim;
  using scalar = Real;

  CELLSPH_HD constexpr Real& operator[](int k) { return c[k]; }
  CELLSPH_HD constexpr const Real& operator[](int k) const { return c[k]; }

  CELLSPH_HD static constexpr Vec zero() { return Vec{}; }
  CELLSPH_HD static constexpr Vec filled(Real v) {
    Vec r;
    for (int k = 0; k < Dim; ++k) r.c[k] = v;
    return r;
  }

  CELLSPH_HD constexpr Vec& operator+=(const Vec& o) {
    for (int k = 0; k < Dim; ++k) c[k] += o.c[k];
    return *this;
  }
  CELLSPH_HD constexpr Vec& operator-=(const Vec& o) {
    for (int k = 0; k < Dim; ++k) c[k] -= o.c[k];
    return *this;
  }
  CELLSPH_HD constexpr Vec& operator*=(Real s) {
    for (int k = 0; k < Dim; ++k) c[k] *= s;
    return *this;
  }
  CELLSPH_HD friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
  CELLSPH_HD friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
  CELLSPH_HD friend constexpr Vec operator*(Vec a, Real s) { return a *= s; }
  CELLSPH_HD friend constexpr Vec operator*(Real s, Vec a) { return a *= s; }
  CELLSPH_HD friend constexpr Vec operator/(Vec a, Real s) { return a *= (Real(1) / s); }
  CELLSPH_HD friend constexpr Vec operator-(Vec a) {
    for (int k = 0; k < Dim; ++k) a.c[k] = -a.c[k];
    return a;
  }
  CELLSPH_HD friend constexpr bool operator==(const Vec& a, const Vec& b) {
    for (int k = 0; k < Dim; ++k)
      if (a.c[k] != b.c[k]) return false;
    return true;
  }
};

template <int Dim, class Real>
CELLSPH_HD constexpr Real dot(const Vec<Dim, Real>& a, const Vec<Dim, Real>& b) {
  Real s = 0;
  for (int k = 0; k < Dim; ++k) s += a.c[k] * b.c[k];
  return s;
}

template <int Dim, class Real>
CELLSPH_HD constexpr Real norm2(const Vec<Dim, Real>& a) {
  return dot(a, a);
}

template <int Dim, class Real>
CELLSPH_HD inline Real norm(const Vec<Dim, Real>& a) {
  return std::sqrt(norm2(a));
}

template <int Dim, class Real>
CELLSPH_HD constexpr Real distance2(const Vec<Dim, Real>& a, const Vec<Dim, Real>& b) {
  Real s = 0;
  for (int k = 0; k < Dim; ++k) {
    const Real d = a.c[k] - b.c[k];
    s += d * d;
  }
  return s;
}

template <int Dim, class Real>
CELLSPH_HD inline bool all_finite(const Vec<Dim, Real>& a) {
  for (int k = 0; k < Dim; ++k)
    if (!std::isfinite(a.c[k])) return false;
  return true;
}

}  // namespace cellsph
