#pragma once
// No fluid particle ends a step past a solid's first layer of wall particles (issue 52 item 1). Whatever
// the wall model, a particle that a splash throws faster than the walls' pressure can stop would end its
// step inside the tank's walls or an obstacle, or beyond them, and fly on alone. After each step's drift,
// a fluid particle deeper than `depth` inside the tank of `boundary.walls` (its open top excepted) or a
// box obstacle at rest (`depth` = half a spacing: the centres of the first layer of wall particles) is
// put back on the surface, `margin` to the fluid side of it, and its velocity into the solid is removed.
// Particles that only sag between the surface and that first layer (the thin front of a surge sliding on
// a floor) are left to the walls' pressure, which pushes them back itself. A run that never needs the
// guard is not changed by it, bit for bit; one that does counts each correction (the progress line and
// the summary say how many; docs/physics.md, "Walls that hold every particle").
#include <cstddef>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

template <int Dim, class Real>
struct SolidGuardPass {
  Vec<Dim, Real>* x;
  Vec<Dim, Real>* v;
  bool container;
  Vec<Dim, Real> lo, hi;  // the tank's inside
  int open_axis;          // the tank's open top is its hi face on this axis; -1: closed
  const GuardBox<Dim, Real>* boxes;
  std::size_t box_count;
  Real depth, margin;

  // 1 where particle i was put back, else 0 (reduce_sum counts them).
  CELLSPH_HD double operator()(std::size_t i) const {
    bool hit = container && keep_inside(x[i], v[i]);
    for (std::size_t k = 0; k < box_count; ++k) hit = keep_outside(x[i], v[i], boxes[k]) || hit;
    return hit ? 1.0 : 0.0;
  }

  CELLSPH_HD bool keep_inside(Vec<Dim, Real>& xi, Vec<Dim, Real>& vi) const {
    bool hit = false;
    for (int a = 0; a < Dim; ++a) {
      if (xi[a] < lo[a] - depth) {
        xi[a] = lo[a] + margin;
        if (vi[a] < 0) vi[a] = 0;
        hit = true;
      }
      if (a != open_axis && xi[a] > hi[a] + depth) {
        xi[a] = hi[a] - margin;
        if (vi[a] > 0) vi[a] = 0;
        hit = true;
      }
    }
    return hit;
  }

  // Deeper than `depth` inside the box: out through the nearest face.
  CELLSPH_HD bool keep_outside(Vec<Dim, Real>& xi, Vec<Dim, Real>& vi, const GuardBox<Dim, Real>& b) const {
    int axis = -1;
    bool low = false;
    Real nearest = 0;
    for (int a = 0; a < Dim; ++a) {
      const Real below = xi[a] - b.lo[a], above = b.hi[a] - xi[a];
      if (!(below > depth && above > depth)) return false;
      const Real d = below < above ? below : above;
      if (axis < 0 || d < nearest) {
        axis = a;
        low = below < above;
        nearest = d;
      }
    }
    if (low) {
      xi[axis] = b.lo[axis] - margin;
      if (vi[axis] > 0) vi[axis] = 0;
    } else {
      xi[axis] = b.hi[axis] + margin;
      if (vi[axis] < 0) vi[axis] = 0;
    }
    return true;
  }
};

template <int Dim, class Real>
SolidGuardPass<Dim, Real> solid_guard(const SolidGuard<Dim, Real>& g, const ParticleView<Dim, Real>& pv) {
  return {pv.x,        pv.v,           g.container,    g.lo,    g.hi,
          g.open_axis, g.boxes.data(), g.boxes.size(), g.depth, g.margin};
}

}  // namespace cellsph
