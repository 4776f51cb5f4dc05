#pragma once
// Small builders of initial particle sets on a lattice, for scenes and tests.
#include <algorithm>
#include <array>
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

// Where a lattice of `spacing` puts its sites along one axis of a block [lo, lo + length]. Where the spacing
// divides the length (to a thousandth of a spacing, which covers a float scene's round-off: a scene at its
// own spacing) there are n = length / spacing sites, site i at lo + (i + 0.5) spacing, as always. Where it
// does not (a scene run at another spacing) the old lattice (round(length / spacing) sites from lo) put its
// last site up to half a spacing from the far face, or beyond it: fluid a third of a spacing from the far
// wall's particles in spheric-test2 at spacing 0.03 was flung at 15.7 m/s (issue 52). Two fits instead:
// - `fluid_lattice_axis` (fluid blocks) keeps n = round(length / spacing) sites as before and stretches
//   their pitch to length / n, so every site is half a pitch inside the faces and the block keeps its volume
//   and its level; the block's masses scale with the pitch (`volume_factor`), so the density stays rho0.
//   (Keeping floor(length / spacing) sites at the spacing, centred, lost up to a spacing of every extent:
//   a third of the paper's coarsened dam break, whose energy then jumped at its first step.)
// - `solid_lattice_axis` (box obstacles, box bodies) keeps floor(length / spacing) sites (at least one) at
//   the spacing, centred: every wall particle at least half a spacing inside the solid's faces.
struct LatticeAxis {
  long n = 1;           // sites
  bool divides = true;  // the spacing divides the length: the sites of lo + (i + 0.5) spacing
  double pitch = 0, offset = 0;

  // Site i, in Real as the lattice has always been computed where the spacing divides the length.
  template <class Real>
  Real site(Real lo, long i) const {
    if (divides) return lo + (Real(i) + Real(0.5)) * static_cast<Real>(pitch);
    return static_cast<Real>(double(lo) + offset + (double(i) + 0.5) * pitch);
  }
};

inline bool spacing_divides(double length, double spacing) {
  return std::abs(length - double(std::lround(length / spacing)) * spacing) <= 1e-3 * spacing;
}

inline LatticeAxis fluid_lattice_axis(double length, double spacing) {
  LatticeAxis a;
  a.pitch = spacing;
  a.divides = spacing_divides(length, spacing);
  a.n = std::lround(length / spacing);  // 0: the block is too thin for a particle (the reader's error)
  if (!a.divides && a.n > 0) a.pitch = length / double(a.n);
  return a;
}

inline LatticeAxis solid_lattice_axis(double length, double spacing) {
  LatticeAxis a;
  a.pitch = spacing;
  a.divides = spacing_divides(length, spacing);
  if (a.divides) {
    a.n = std::lround(length / spacing);
  } else {
    a.n = std::max(static_cast<long>(std::floor(length / spacing)),
                   std::min(std::lround(length / spacing), 1L));
    a.offset = 0.5 * (length - double(a.n) * spacing);
  }
  return a;
}

// The mass of a particle of a lattice with these axes over that of the plain lattice of `spacing`: the
// product of the pitches over the spacing (1 where every axis divides).
template <int Dim>
double volume_factor(const std::array<LatticeAxis, 3>& axes, double spacing) {
  double f = 1;
  for (int a = 0; a < Dim; ++a) f *= axes[static_cast<std::size_t>(a)].pitch / spacing;
  return f;
}

enum class LatticeFit { Fluid, Solid };

// The lattice of the box [lo, hi] along each of its Dim axes (the others one site of pitch `spacing`).
template <int Dim>
std::array<LatticeAxis, 3> lattice_of(const double* lo, const double* hi, double spacing, LatticeFit fit) {
  std::array<LatticeAxis, 3> axes{};
  for (auto& a : axes) a.pitch = spacing;
  for (int a = 0; a < Dim; ++a)
    axes[static_cast<std::size_t>(a)] = fit == LatticeFit::Fluid ? fluid_lattice_axis(hi[a] - lo[a], spacing)
                                                                 : solid_lattice_axis(hi[a] - lo[a], spacing);
  return axes;
}

template <int Dim, class Real>
std::array<LatticeAxis, 3> lattice_of(const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi, Real spacing,
                                      LatticeFit fit) {
  double l[Dim], h[Dim];
  for (int a = 0; a < Dim; ++a) {
    l[a] = double(lo[a]);
    h[a] = double(hi[a]);
  }
  return lattice_of<Dim>(l, h, double(spacing), fit);
}

// Fills [lo, hi] with fluid particles on the fluid lattice of `spacing` (fluid_lattice_axis: stretched where
// the spacing does not divide the block), each of mass `mass` (0: the phase's mass; a stretched lattice wants
// the phase's mass times volume_factor). Returns the number of particles added.
template <int Dim, class Real>
std::size_t add_block(Particles<Dim, Real>& p, const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi,
                      Real spacing, std::int32_t phase, Real mass = 0) {
  const auto ax = lattice_of(lo, hi, spacing, LatticeFit::Fluid);
  std::size_t added = 0;
  for (long k = 0; k < (Dim == 3 ? ax[2].n : 1); ++k)
    for (long j = 0; j < ax[1].n; ++j)
      for (long i = 0; i < ax[0].n; ++i) {
        const long idx[3] = {i, j, k};
        Vec<Dim, Real> x;
        for (int a = 0; a < Dim; ++a) x[a] = ax[static_cast<std::size_t>(a)].site(lo[a], idx[a]);
        add_particle(p, x, phase, ParticleKind::Fluid, mass);
        ++added;
      }
  return added;
}

// Appends `layers` layers of boundary particles (Akinci 2012) on the lattice of `spacing` from lo around the
// box [lo, hi], a spacing apart outwards from each face: where the spacing does not divide an extent the
// layers beyond hi start half a spacing past hi (not where the lattice from lo would put them). With open_top
// the face at hi[up] is left open (the side walls stop at its height). weight 0 lets the Simulation compute
// Akinci's psi_b; rho0 spacing^Dim makes a wall at least one support length thick behave like resting
// fluid. `up`: the axis whose upper face open_top leaves open (the one gravity points against).
template <int Dim, class Real>
std::size_t add_box_walls(Particles<Dim, Real>& p, const Vec<Dim, Real>& lo, const Vec<Dim, Real>& hi,
                          Real spacing, int layers, bool open_top, std::int32_t phase = 0, Real weight = 0,
                          int up = Dim - 1) {
  int n[3] = {1, 1, 1};  // round(extent / spacing) sites inside the box along each axis
  bool divides[3] = {true, true, true};
  for (int a = 0; a < Dim; ++a) {
    n[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / spacing));
    divides[a] = spacing_divides(double(hi[a]) - double(lo[a]), double(spacing));
  }
  auto coordinate = [&](int a, int idx) {
    if (divides[a] || idx < n[a]) return lo[a] + (Real(idx) + Real(0.5)) * spacing;
    return hi[a] + (Real(idx - n[a]) + Real(0.5)) * spacing;
  };
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
        for (int a = 0; a < Dim; ++a) x[a] = coordinate(a, idx[a]);
        add_particle(p, x, phase, ParticleKind::Boundary, weight);
        ++added;
      }
    }
  return added;
}

}  // namespace cellsph
