#pragma once
// Point sets shared by tests, benchmarks and `cellsph bench neighbors`. Deterministic for a seed.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "cellsph/core/vec.hpp"

namespace cellsph::point_sets {

// Jittered lattice of n points (rounded down to a full block), spacing s, jitter +-jitter*s on
// every axis. The block is as close to a cube (square in 2D) as possible.
template <int Dim, class Real>
std::vector<Vec<Dim, Real>> jittered_lattice(std::size_t n, Real s, Real jitter, std::uint64_t seed = 1) {
  const auto side = static_cast<std::size_t>(std::floor(std::pow(double(n), 1.0 / Dim) + 1e-9));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec<Dim, Real>> x;
  std::size_t total = 1;
  for (int k = 0; k < Dim; ++k) total *= side;
  x.reserve(total);
  for (std::size_t idx = 0; idx < total; ++idx) {
    std::size_t r = idx;
    Vec<Dim, Real> p;
    for (int k = 0; k < Dim; ++k) {
      const std::size_t c = r % side;
      r /= side;
      p[k] = static_cast<Real>((double(c) + double(jitter) * u(rng)) * double(s));
    }
    x.push_back(p);
  }
  return x;
}

// n points uniformly random in a box with the density of a lattice of spacing s.
template <int Dim, class Real>
std::vector<Vec<Dim, Real>> uniform_random(std::size_t n, Real s, std::uint64_t seed = 2) {
  const double side = std::pow(double(n), 1.0 / Dim) * double(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, side);
  std::vector<Vec<Dim, Real>> x(n);
  for (auto& p : x)
    for (int k = 0; k < Dim; ++k) p[k] = static_cast<Real>(u(rng));
  return x;
}

// uniform_random's points sorted into cell order: by the cell of side `cell` s each lies in, the last
// axis slowest (x fastest), as a simulation that reorders its particles holds them. A search that
// reads candidates by particle index sees them close in memory.
template <int Dim, class Real>
std::vector<Vec<Dim, Real>> uniform_in_cell_order(std::size_t n, Real s, double cell = 2,
                                                  std::uint64_t seed = 2) {
  auto x = uniform_random<Dim, Real>(n, s, seed);
  const double side = std::pow(double(n), 1.0 / Dim) * double(s), w = cell * double(s);
  const auto cells = static_cast<std::uint64_t>(std::ceil(side / w)) + 1;
  auto key = [&](const Vec<Dim, Real>& p) {
    std::uint64_t k = 0;
    for (int a = Dim - 1; a >= 0; --a) k = k * cells + static_cast<std::uint64_t>(double(p[a]) / w);
    return k;
  };
  std::stable_sort(x.begin(), x.end(), [&](const auto& a, const auto& b) { return key(a) < key(b); });
  return x;
}

// n points in Gaussian blobs inside the box of uniform_random: `blobs` centres, each blob's
// standard deviation a tenth of the box side. Density varies by orders of magnitude.
template <int Dim, class Real>
std::vector<Vec<Dim, Real>> clustered(std::size_t n, Real s, int blobs = 8, std::uint64_t seed = 3) {
  const double side = std::pow(double(n), 1.0 / Dim) * double(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.2 * side, 0.8 * side);
  std::normal_distribution<double> g(0.0, 0.1 * side);
  std::vector<Vec<Dim, double>> centres(static_cast<std::size_t>(blobs));
  for (auto& c : centres)
    for (int k = 0; k < Dim; ++k) c[k] = u(rng);
  std::vector<Vec<Dim, Real>> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = centres[i % centres.size()];
    for (int k = 0; k < Dim; ++k) x[i][k] = static_cast<Real>(c[k] + g(rng));
  }
  return x;
}

// The dam-break set of the paper's section 5 (Table 1): 1600 particles with rest density
// rho_0 = 1000 kg/m^3, mass m = 0.0012 kg and support length h = 0.05 m (kPaperDamBreakH). Density
// and mass are volumetric, so the set is 3D with particle spacing (m / rho_0)^(1/3) = 0.010627 m;
// the particles fill a column of 10 (x) by 20 (y, up) by 8 (z) lattice sites from the origin.
// At that spacing h reaches about 4.7 spacings: an interior particle has 460 neighbours.
inline constexpr double kPaperDamBreakH = 0.05;
inline constexpr int kPaperDamBreakBlock[3] = {10, 20, 8};

template <int Dim, class Real>
std::vector<Vec<Dim, Real>> paper_dam_break() {
  static_assert(Dim == 3, "the paper's dam-break set is volumetric (kg/m^3): 3D only");
  const double spacing = std::cbrt(0.0012 / 1000.0);
  std::vector<Vec<Dim, Real>> x;
  x.reserve(1600);
  for (int k = 0; k < kPaperDamBreakBlock[2]; ++k)
    for (int j = 0; j < kPaperDamBreakBlock[1]; ++j)
      for (int i = 0; i < kPaperDamBreakBlock[0]; ++i)
        x.push_back(Vec<Dim, Real>{{static_cast<Real>(i * spacing), static_cast<Real>(j * spacing),
                                    static_cast<Real>(k * spacing)}});
  return x;
}

}  // namespace cellsph::point_sets
