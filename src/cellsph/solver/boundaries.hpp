#pragma once
// Wall responses applied to one particle after its position update.
#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

// The write-up's box: clamp the coordinate onto [lo + r, hi - r] and multiply that velocity component by
// `damping` (negative: the particle bounces back with a fraction of its speed).
template <int Dim, class Real>
CELLSPH_HD inline void box_collision(Vec<Dim, Real>& x, Vec<Dim, Real>& v, const Vec<Dim, Real>& lo,
                                     const Vec<Dim, Real>& hi, Real radius, Real damping) {
  for (int a = 0; a < Dim; ++a) {
    if (x[a] > hi[a] - radius) {
      x[a] = hi[a] - radius;
      v[a] *= damping;
    }
    if (x[a] < lo[a] + radius) {
      x[a] = lo[a] + radius;
      v[a] *= damping;
    }
  }
}

// The paper's wall (section 5): a particle behind the plane dot(n, x) = offset is projected back onto it
// (no overshooting), its approaching normal velocity reversed with restitution e (inelastic collision)
// and its tangential velocity reduced by the fraction `friction` (wet friction).
template <int Dim, class Real>
CELLSPH_HD inline void plane_collision(Vec<Dim, Real>& x, Vec<Dim, Real>& v, const Vec<Dim, Real>& n,
                                       Real offset, Real restitution, Real friction) {
  const Real d = dot(n, x) - offset;
  if (d >= 0) return;
  x -= n * d;
  const Real vn = dot(v, n);
  if (vn >= 0) return;
  const Vec<Dim, Real> vt = v - n * vn;
  v = vt * (1 - friction) + n * (-restitution * vn);
}

}  // namespace cellsph
