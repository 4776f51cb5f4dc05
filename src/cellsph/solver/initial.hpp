#pragma once
// Small builders of initial particle sets on a lattice, for scenes and tests.
#include <cmath>
#include <cstdint>

#include "cellsph/core/vec.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

// Appends one particle (all other fields zero: the Simulation completes them from the phase table).
template <int Dim, class Real>
void add_particle(Particles<Dim, Real>& p, const Vec<Dim, Real>& x, std::int32_t phase, ParticleKind kind,
                  Real mass = 0, const Vec<Dim, Real>& v = {}) {
  const std::size_t i = p.size();
  p.resize(i + 1);
  p.x[i] = x;
  p.v[i] = v;
  p.m[i] = mass;
  p.phase[i] = phase;
  p.kind[i] = static_cast<std::uint8_t>(kind);
}

// Fills [lo, hi] with fluid particles at the centres of a lattice of cells of size `spacing`, each of
// mass `mass` (0: the phase's mass). Returns the number of particles added.
template <int Dim, class Real>
std::size_t add_block(Particles<Dim, Real>& p, const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi,
                      Real spacing, std::int32_t phase, Real mass = 0) {
  int n[3] = {1, 1, 1};
  for (int a = 0; a < Dim; ++a) n[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / spacing));
  std::size_t added = 0;
  for (int k = 0; k < (Dim == 3 ? n[2] : 1); ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int idx[3] = {i, j, k};
        Vec<Dim, Real> x;
        for (int a = 0; a < Dim; ++a) x[a] = lo[a] + (Real(idx[a]) + Real(0.5)) * spacing;
        add_particle(p, x, phase, ParticleKind::Fluid, mass);
        ++added;
      }
  return added;
}

// Appends `layers` layers of boundary particles (Akinci 2012) on the lattice of add_block around the box
// [lo, hi]; with open_top the face at hi[Dim-1] is left open (the side walls stop at its height).
// weight 0 lets the Simulation compute Akinci's psi_b; rho0 spacing^Dim makes a wall at least one support
// length thick behave like resting fluid.
template <int Dim, class Real>
// `up`: the axis whose upper face open_top leaves open (the one gravity points against).
std::size_t add_box_walls(Particles<Dim, Real>& p, const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi,
                          Real spacing, int layers, bool open_top, std::int32_t phase = 0, Real weight = 0,
                          int up = Dim - 1) {
  int n[3] = {1, 1, 1};
  for (int a = 0; a < Dim; ++a) n[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / spacing));
  const int L = layers;
  std::size_t added = 0;
  const int k0 = Dim == 3 ? -L : 0, k1 = Dim == 3 ? n[2] + L : 1;
  for (int k = k0; k < k1; ++k)
    for (int j = -L; j < n[1] + L; ++j) {
      // Inside the box along the other axes, a row is wall only in its first and last L sites: skip
      // its inside, so the loop costs the walls' size, not the box's volume.
      const bool row_inside = j >= 0 && j < n[1] && (Dim == 2 || (k >= 0 && k < n[2]));
      for (int i = -L; i < n[0] + L; ++i) {
        if (row_inside && i == 0) i = n[0];
        const int idx[3] = {i, j, k};
        bool wall = false;
        for (int a = 0; a < Dim; ++a) wall = wall || idx[a] < 0 || idx[a] >= n[a];
        if (!wall) continue;
        if (open_top && idx[up] >= n[up]) continue;
        Vec<Dim, Real> x;
        for (int a = 0; a < Dim; ++a) x[a] = lo[a] + (Real(idx[a]) + Real(0.5)) * spacing;
        add_particle(p, x, phase, ParticleKind::Boundary, weight);
        ++added;
      }
    }
  return added;
}

}  // namespace cellsph
