#pragma once
// Shared by the io tests only: particles with a distinct, non-round value in every field and a temporary
// folder that is removed afterwards.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cellsph/core/temp_dir_test_util.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph::test {

// Values chosen so that a lost digit or a swapped field shows: thirds are not exact in binary.
template <int Dim, class Real>
Particles<Dim, Real> make_particles(std::size_t n) {
  Particles<Dim, Real> p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Real t = static_cast<Real>(i) + Real(1) / Real(3);
    for (int k = 0; k < Dim; ++k) {
      p.x[i][k] = t * Real(0.01) + Real(k);
      p.v[i][k] = -t * Real(0.5) + Real(10 * k);
      p.f[i][k] = t * Real(7) - Real(k);
    }
    p.m[i] = Real(0.001) * t;
    p.rho[i] = Real(1000) + t;
    p.p[i] = Real(-50) + Real(3) * t;
    p.h[i] = Real(0.02) + Real(1e-4) * t;
    p.color[i] = Real(0.5) / (t + Real(1));
    p.mu[i] = Real(1e-3) * (Real(1) + t);
    p.phase[i] = static_cast<std::int32_t>(i % 3);
    p.level[i] = static_cast<std::int32_t>(i % 5) - 1;
    p.id[i] = static_cast<std::uint32_t>(i);  // the identity: writers need not reorder
  }
  return p;
}

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void spit(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace cellsph::test
