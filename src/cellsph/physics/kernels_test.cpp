// Kernel identities checked against references computed here, independently of the kernel code:
// quadrature for the normalisation, finite differences of W for the gradient and the Laplacian.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>

#include "cellsph/physics/kernels.hpp"

namespace cellsph {
namespace {

constexpr double kH = 0.7;

// Integral of W over R^Dim on a Cartesian midpoint grid (never samples r = 0).
template <int Dim, class K>
double grid_integral(const K& k, int n) {
  const double d = 2 * kH / n;
  double s = 0;
  if constexpr (Dim == 2) {
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double x = -kH + (a + 0.5) * d, y = -kH + (b + 0.5) * d;
        s += k.W(std::sqrt(x * x + y * y));
      }
    return s * d * d;
  } else {
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int c = 0; c < n; ++c) {
          const double x = -kH + (a + 0.5) * d, y = -kH + (b + 0.5) * d, z = -kH + (c + 0.5) * d;
          s += k.W(std::sqrt(x * x + y * y + z * z));
        }
    return s * d * d * d;
  }
}

// Integral over shells: 2 pi r dr in 2D, 4 pi r^2 dr in 3D, composite midpoint rule.
template <int Dim, class K>
double radial_integral(const K& k, int n) {
  const double dr = kH / n;
  double s = 0;
  for (int i = 0; i < n; ++i) {
    const double r = (i + 0.5) * dr;
    s += k.W(r) * (Dim == 2 ? 2 * std::numbers::pi * r : 4 * std::numbers::pi * r * r);
  }
  return s * dr;
}

template <int Dim>
Vec<Dim, double> sample_point(int i) {
  // A few fixed directions and radii, away from r = 0, the support edge and the spline's knot at h/2.
  static const double radii[] = {0.13, 0.29, 0.41, 0.52, 0.63};
  Vec<Dim, double> v;
  for (int k = 0; k < Dim; ++k) v[k] = std::sin(1.3 * i + 2.1 * k + 0.4);
  return v * (radii[i % 5] * kH / norm(v));
}

template <int Dim, class K>
void check_kernel(const K& k, bool smooth_at_origin, bool has_laplacian) {
  SCOPED_TRACE(::testing::Message() << "Dim " << Dim);
  EXPECT_NEAR(radial_integral<Dim>(k, 200000), 1.0, 2e-5);
  if (smooth_at_origin) {
    EXPECT_NEAR(grid_integral<Dim>(k, Dim == 2 ? 800 : 160), 1.0, 2e-3);
  }

  // Compact support and symmetry.
  EXPECT_EQ(k.W(kH * 1.0001), 0.0);
  EXPECT_EQ(k.W(3 * kH), 0.0);
  Vec<Dim, double> out;
  out[0] = kH * 1.01;
  EXPECT_EQ(norm2(k.gradW(out)), 0.0);
  if (has_laplacian) {
    EXPECT_EQ(k.laplacian(kH * 1.01), 0.0);
  }

  const double e = 1e-5;
  for (int i = 0; i < 10; ++i) {
    const auto x = sample_point<Dim>(i);
    EXPECT_DOUBLE_EQ(k.W(norm(x)), k.W(norm(-x)));
    const auto g = k.gradW(x), gm = k.gradW(-x);
    double lap_fd = 0;
    for (int a = 0; a < Dim; ++a) {
      EXPECT_DOUBLE_EQ(g[a], -gm[a]);
      auto xp = x, xm = x;
      xp[a] += e;
      xm[a] -= e;
      const double wp = k.W(norm(xp)), wm = k.W(norm(xm)), w0 = k.W(norm(x));
      const double fd = (wp - wm) / (2 * e);
      EXPECT_NEAR(g[a], fd, 1e-6 * (1 + std::abs(fd)) * 100) << "point " << i << " axis " << a;
      lap_fd += (wp - 2 * w0 + wm) / (e * e);
    }
    if (has_laplacian) {
      EXPECT_NEAR(k.laplacian(norm(x)), lap_fd, 1e-4 * (1 + std::abs(lap_fd))) << "point " << i;
    }
  }
}

TEST(Kernels, Poly6) {
  check_kernel<2>(Poly6Kernel<2, double>(kH), true, true);
  check_kernel<3>(Poly6Kernel<3, double>(kH), true, true);
}
TEST(Kernels, Spiky) {
  check_kernel<2>(SpikyKernel<2, double>(kH), true, true);
  check_kernel<3>(SpikyKernel<3, double>(kH), true, true);
}
TEST(Kernels, ViscosityMueller) {
  // Singular at the origin: normalisation by the radial rule only.
  check_kernel<2>(ViscosityKernel<2, double>(kH), false, true);
  check_kernel<3>(ViscosityKernel<3, double>(kH), false, true);
  // eq. 18 form of the Laplacian, 45/(pi h^6)(h - r) in 3D.
  const double lap_ref = 45 / (std::numbers::pi * std::pow(kH, 6)) * (kH - 0.2);
  const ViscosityKernel<3, double> kv(kH);
  EXPECT_NEAR(kv.laplacian(0.2), lap_ref, 1e-9);
  // Positive inside the support: viscosity never accelerates relative motion.
  const ViscosityKernel<2, double> k2(kH);
  const ViscosityKernel<3, double> k3(kH);
  EXPECT_GT(k2.W(0.99 * kH), 0);
  EXPECT_GT(k3.W(0.99 * kH), 0);
}
TEST(Kernels, CubicSpline) {
  check_kernel<2>(CubicSplineKernel<2, double>(kH), true, true);
  check_kernel<3>(CubicSplineKernel<3, double>(kH), true, true);
}
TEST(Kernels, WendlandC2) {
  check_kernel<2>(WendlandC2Kernel<2, double>(kH), true, true);
  check_kernel<3>(WendlandC2Kernel<3, double>(kH), true, true);
}

TEST(Kernels, Poly6LaplacianMatchesCudaWriteupConstant) {
  // The write-up's Poly6Laplacian constant -945/(32 pi h^9) times (h^2-r^2)(3h^2-7r^2).
  const double r = 0.3, h2 = kH * kH;
  const double ref = -945 / (32 * std::numbers::pi * std::pow(kH, 9)) * (h2 - r * r) * (3 * h2 - 7 * r * r);
  const Poly6Kernel<3, double> k(kH);
  EXPECT_NEAR(k.laplacian(r), ref, 1e-9 * std::abs(ref));
}

// Akinci 2013's cohesion spline: the printed 3D form integrates to 79/336 over space (the polynomial
// integrated by hand: 128 (79 / 43008)); the 2D normalisation gives the same over the plane. Continuous
// at the knot h/2, zero at h, repulsive near 0, attractive beyond h/2, the printed 3D constant.
TEST(Kernels, AkinciCohesion) {
  struct AsW3 {
    CohesionKernel<3, double> c{kH};
    double W(double r) const { return c.C(r); }
  };
  struct AsW2 {
    CohesionKernel<2, double> c{kH};
    double W(double r) const { return c.C(r); }
  };
  EXPECT_NEAR(radial_integral<3>(AsW3{}, 200000), 79.0 / 336.0, 1e-8);
  EXPECT_NEAR(radial_integral<2>(AsW2{}, 200000), 79.0 / 336.0, 1e-8);
  const CohesionKernel<3, double> c(kH);
  EXPECT_DOUBLE_EQ(c.norm, 32 / (std::numbers::pi * std::pow(kH, 9)));
  EXPECT_NEAR(c.C(kH / 2 * (1 - 1e-12)), c.C(kH / 2 * (1 + 1e-12)), 1e-9 * std::abs(c.C(kH / 2)));
  EXPECT_EQ(c.C(kH), 0.0);
  EXPECT_EQ(c.C(1.01 * kH), 0.0);
  EXPECT_LT(c.C(0.1 * kH), 0.0);
  EXPECT_GT(c.C(0.7 * kH), 0.0);
}

TEST(Kernels, FloatMatchesDouble) {
  const Poly6Kernel<3, float> kf(0.7f);
  const Poly6Kernel<3, double> kd(kH);
  EXPECT_NEAR(kf.W(0.3f), kd.W(0.3), 1e-5 * kd.W(0.3));
}

// gradW_factor is the scalar of the gradient: r * gradW_factor(r) has gradW(r)'s bits for every kernel,
// dimension and precision inside the support, and is zero beyond it (models/dfsph.hpp stores the scalar and
// rebuilds the vector, and relies on it for results identical to recomputing gradW).
// Uniform samples in [0, 1) from a fixed LCG: the same samples on every platform.
struct Lcg {
  std::uint64_t state;
  double operator()() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(1ull << 53);
  }
};

constexpr KernelKind kAllKernels[] = {KernelKind::Poly6, KernelKind::Spiky, KernelKind::Viscosity,
                                      KernelKind::CubicSpline, KernelKind::WendlandC2};

template <int Dim, class Real>
void check_gradient_factor() {
  Lcg uniform{12345};
  for (const KernelKind kind : kAllKernels) {
    with_kernel<Dim, Real>(kind, Real(kH), [&](const auto w) {
      for (int k = 0; k < 2000; ++k) {
        Vec<Dim, Real> rv;
        for (int a = 0; a < Dim; ++a) rv[a] = Real((2 * uniform() - 1) * 1.2 * kH);
        const auto g = w.gradW(rv);
        const auto rebuilt = rv * w.gradW_factor(rv);
        const bool inside = norm(rv) <= Real(kH);
        for (int a = 0; a < Dim; ++a) {
          if (inside)
            ASSERT_EQ(std::memcmp(&g[a], &rebuilt[a], sizeof(Real)), 0)
                << kernel_name(kind) << " " << Dim << "D sample " << k << " axis " << a << ": " << g[a]
                << " vs " << rebuilt[a];
          else  // beyond the support both are zero (x_ij * 0 may be -0)
            ASSERT_TRUE(g[a] == 0 && rebuilt[a] == 0) << kernel_name(kind) << " sample " << k;
        }
      }
    });
  }
}

TEST(Kernels, GradientFactorRebuildsTheGradientsBits) {
  check_gradient_factor<2, float>();
  check_gradient_factor<2, double>();
  check_gradient_factor<3, float>();
  check_gradient_factor<3, double>();
}

// kernel_value_and_factor (one square root, selects for branches) gives W2's and gradW_factor's bits, at
// random points, at r = 0, at the cubic spline's seam q = 1/2 and at the support's edge.
template <int Dim, class Real>
void check_value_and_factor() {
  Lcg uniform{777};
  for (const KernelKind kind : kAllKernels) {
    with_kernel<Dim, Real>(kind, Real(kH), [&](const auto w) {
      for (int k = 0; k < 2004; ++k) {
        Vec<Dim, Real> rv{};
        if (k < 2000) {
          for (int a = 0; a < Dim; ++a) rv[a] = Real((2 * uniform() - 1) * 1.2 * kH);
        } else if (k > 2000) {  // 0.5 h, h, and the next value past h
          rv[0] = k == 2001 ? Real(kH / 2) : k == 2002 ? Real(kH) : std::nextafter(Real(kH), Real(1));
        }
        const Real r2 = norm2(rv);
        const auto both = kernel_value_and_factor(w, rv, r2);
        const Real value = w.W2(r2), factor = w.gradW_factor(rv);
        ASSERT_EQ(std::memcmp(&both.value, &value, sizeof(Real)), 0)
            << kernel_name(kind) << " " << Dim << "D sample " << k << ": W " << both.value << " vs " << value;
        ASSERT_TRUE(both.factor == factor)  // equal, and the same bits unless both are zero (-0 == 0)
            << kernel_name(kind) << " " << Dim << "D sample " << k << ": W'/r " << both.factor << " vs "
            << factor;
        if (factor != 0) {
          ASSERT_EQ(std::memcmp(&both.factor, &factor, sizeof(Real)), 0) << kernel_name(kind);
        }
      }
    });
  }
}

TEST(Kernels, ValueAndFactorHaveTheSeparateFunctionsBits) {
  check_value_and_factor<2, float>();
  check_value_and_factor<2, double>();
  check_value_and_factor<3, float>();
  check_value_and_factor<3, double>();
}

TEST(Kernels, NamesRoundTrip) {
  for (auto k : {KernelKind::Poly6, KernelKind::Spiky, KernelKind::Viscosity, KernelKind::CubicSpline,
                 KernelKind::WendlandC2})
    EXPECT_EQ(parse_kernel(kernel_name(k)), k);
  EXPECT_FALSE(parse_kernel("gauss"));
}

}  // namespace
}  // namespace cellsph
