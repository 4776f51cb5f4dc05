#pragma once
// No fluid particle ends a step past a solid's first layer of wall particles (issue 52 item 1). Whatever
// the wall model, a particle that a splash throws faster than the walls' pressure can stop would end its
// step inside the tank's walls or an obstacle, or beyond them, and fly on alone. After each step's drift:
//  * a particle that ends deeper than `depth` (half a spacing: the centres of the first layer of wall
//    particles) inside a solid is put back on its surface, `margin` to the fluid side, and its velocity
//    into the solid (relative to the solid's own, where it moves) is removed. The solids: the tank of
//    `boundary.walls` (its open top excepted), box obstacles and box bodies (exact faces), and shaped
//    obstacles, containers and bodies (spheres, cylinders, meshes: their signed distance sampled on a grid,
//    GuardGrid, interpolated multilinearly, its gradient the way out);
//  * a fast particle (one that moved more than `depth` in the step) is also followed along its drift from
//    where it started (x - dt v), in samples a quarter spacing apart: where the path first goes deeper than
//    `depth` into a solid, or into one deeper than `depth` / 2 and out again (through a wall one spacing
//    thick), the particle stops at the last sample before it went in, so it cannot cross a thin obstacle
//    or a container's wall whole in one step;
//  * moving solids (prescribed motions, floating bodies) are tested in their own frame (GuardFrame), where
//    the scene placed them.
// Particles that only sag between the surface and the first layer (the thin front of a surge sliding on a
// floor) are left to the walls' pressure, which pushes them back itself. A run that never needs the guard
// is not changed by it, bit for bit; one that does counts each correction (the progress line and the
// summary say how many; docs/physics.md, "Walls that hold every particle").
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "cellsph/core/hd.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

namespace guard_detail {

// The most samples a fast particle's path is followed in (a quarter spacing apart: 16 spacings in a step,
// past which the run has blown up and the stability check says so).
inline constexpr int kMaxSweptSteps = 64;

// The velocity at world point x of the solid that moves with frame f.
template <int Dim, class Real>
CELLSPH_HD Vec<Dim, Real> frame_velocity(const GuardFrame& f, const Vec<Dim, Real>& x) {
  double r[3] = {0, 0, 0};
  for (int a = 0; a < Dim; ++a) r[a] = static_cast<double>(x[a]) - f.c[a];
  const double wr[3] = {f.w[1] * r[2] - f.w[2] * r[1], f.w[2] * r[0] - f.w[0] * r[2],
                        f.w[0] * r[1] - f.w[1] * r[0]};
  Vec<Dim, Real> out;
  for (int a = 0; a < Dim; ++a) out[a] = static_cast<Real>(f.u[a] + wr[a]);
  return out;
}

// World point x in the frame where the scene placed the solid: R^T (x - b).
template <int Dim, class Real>
CELLSPH_HD Vec<Dim, Real> to_rest(const GuardFrame& f, const Vec<Dim, Real>& x) {
  double d[3] = {0, 0, 0};
  for (int a = 0; a < Dim; ++a) d[a] = static_cast<double>(x[a]) - f.b[a];
  Vec<Dim, Real> out;
  for (int a = 0; a < Dim; ++a) {
    double s = 0;
    for (int k = 0; k < 3; ++k) s += f.R[3 * k + a] * d[k];
    out[a] = static_cast<Real>(s);
  }
  return out;
}

// A direction of the rest frame in the world (R n), or back (R^T n).
template <int Dim, class Real>
CELLSPH_HD Vec<Dim, Real> turn(const GuardFrame& f, const Vec<Dim, Real>& n, bool back) {
  Vec<Dim, Real> out;
  for (int a = 0; a < Dim; ++a) {
    double s = 0;
    for (int k = 0; k < Dim; ++k) s += (back ? f.R[3 * k + a] : f.R[3 * a + k]) * static_cast<double>(n[k]);
    out[a] = static_cast<Real>(s);
  }
  return out;
}

template <int Dim, class Real>
CELLSPH_HD Vec<Dim, Real> to_world(const GuardFrame& f, const Vec<Dim, Real>& xr) {
  Vec<Dim, Real> out = turn(f, xr, false);
  for (int a = 0; a < Dim; ++a) out[a] = static_cast<Real>(static_cast<double>(out[a]) + f.b[a]);
  return out;
}

}  // namespace guard_detail

template <int Dim, class Real>
struct SolidGuardPass {
  using V = Vec<Dim, Real>;
  V* x;
  V* v;
  bool container;
  V lo, hi;       // the tank's inside
  int open_axis;  // the tank's open top is its hi face on this axis; -1: closed
  const GuardBox<Dim, Real>* boxes;
  std::size_t box_count;
  const GuardGrid<Dim, Real>* grids;
  std::size_t grid_count;
  const Real* grid_values;
  const GuardFrame* frames;  // this step's frames of the moving solids (GuardMover::frame)
  std::int32_t motions;      // how many of them are prescribed motions (the bodies' come after)
  Real depth, margin;
  Real dt;  // the step's drift: the particle started the step at x - dt v (0: not followed)

  // 1 where particle i was put back, else 0 (reduce_sum counts them).
  CELLSPH_HD double operator()(std::size_t i) const {
    V xi = x[i], vi = v[i];
    bool hit = follow(xi, vi);
    hit = (container && keep_inside(xi, vi)) || hit;
    for (std::size_t k = 0; k < box_count; ++k) hit = keep_out_of_box(xi, vi, boxes[k]) || hit;
    for (std::size_t k = 0; k < grid_count; ++k) hit = keep_out_of_grid(xi, vi, grids[k]) || hit;
    if (!hit) return 0.0;
    x[i] = xi;
    v[i] = vi;
    return 1.0;
  }

  CELLSPH_HD bool keep_inside(V& xi, V& vi) const {
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

  // Deeper than `depth` inside the box [lo, hi] (its rest frame): out through the nearest face.
  CELLSPH_HD bool keep_outside(V& xi, V& vi, const V& blo, const V& bhi) const {
    int axis = -1;
    const bool low = nearest_face(xi, blo, bhi, axis);
    if (axis < 0) return false;
    if (low) {
      xi[axis] = blo[axis] - margin;
      if (vi[axis] > 0) vi[axis] = 0;
    } else {
      xi[axis] = bhi[axis] + margin;
      if (vi[axis] < 0) vi[axis] = 0;
    }
    return true;
  }

  // Whether xi is nearer the box's lo face than its hi face on `axis`, the axis of the nearest face when xi
  // is deeper than `depth` inside (else axis stays -1).
  CELLSPH_HD bool nearest_face(const V& xi, const V& blo, const V& bhi, int& axis) const {
    bool low = false;
    Real nearest = 0;
    for (int a = 0; a < Dim; ++a) {
      const Real below = xi[a] - blo[a], above = bhi[a] - xi[a];
      if (!(below > depth && above > depth)) {
        axis = -1;
        return false;
      }
      const Real d = below < above ? below : above;
      if (axis < 0 || d < nearest) {
        axis = a;
        low = below < above;
        nearest = d;
      }
    }
    return low;
  }

  CELLSPH_HD bool keep_out_of_box(V& xi, V& vi, const GuardBox<Dim, Real>& b) const {
    const std::int32_t f = b.mover.frame(motions);
    if (f < 0) return keep_outside(xi, vi, b.lo, b.hi);
    // In the box's frame, with the velocity relative to it.
    using namespace guard_detail;
    const GuardFrame& fr = frames[f];
    V xr = to_rest(fr, xi);
    const V vw = frame_velocity(fr, xi);
    V vr = turn(fr, vi - vw, true);
    if (!keep_outside(xr, vr, b.lo, b.hi)) return false;
    xi = to_world(fr, xr);
    vi = turn(fr, vr, false) + frame_velocity(fr, xi);
    return true;
  }

  // The signed distance to grid g's surface at rest-frame point p (positive on the fluid's side) and its
  // gradient; false off the grid.
  CELLSPH_HD bool sample(const GuardGrid<Dim, Real>& g, const V& p, Real& phi, V& grad) const {
    std::int64_t cell[3] = {0, 0, 0};
    Real t[3] = {0, 0, 0};
    for (int a = 0; a < Dim; ++a) {
      const Real f = (p[a] - g.origin[a]) / g.pitch;
      if (!(f >= 0 && f <= Real(g.n[a] - 1))) return false;
      std::int64_t c = static_cast<std::int64_t>(f);
      if (c > g.n[a] - 2) c = g.n[a] - 2;
      cell[a] = c;
      t[a] = f - static_cast<Real>(c);
    }
    phi = 0;
    for (int a = 0; a < Dim; ++a) grad[a] = 0;
    for (int corner = 0; corner < (1 << Dim); ++corner) {
      std::uint64_t idx = g.first, stride = 1;
      Real w = 1;
      Real dw[3] = {1, 1, 1};  // d w / d t_a, as products
      for (int a = 0; a < Dim; ++a) {
        const bool up = (corner >> a) & 1;
        idx += static_cast<std::uint64_t>(cell[a] + (up ? 1 : 0)) * stride;
        stride *= static_cast<std::uint64_t>(g.n[a]);
        const Real wa = up ? t[a] : 1 - t[a];
        for (int b = 0; b < Dim; ++b) dw[b] *= (a == b) ? (up ? Real(1) : Real(-1)) : wa;
        w *= wa;
      }
      const Real value = grid_values[idx];
      phi += w * value;
      for (int a = 0; a < Dim; ++a) grad[a] += dw[a] * value / g.pitch;
    }
    return true;
  }

  // Deeper than `depth` into grid g's solid: back along its distance's gradient onto the surface, or,
  // deeper than the grid's band (no direction there), to where the step started it, at the solid's speed.
  CELLSPH_HD bool keep_out_of_grid(V& xi, V& vi, const GuardGrid<Dim, Real>& g) const {
    using namespace guard_detail;
    const std::int32_t f = g.mover.frame(motions);
    const V xr = f < 0 ? xi : to_rest(frames[f], xi);
    Real phi = -g.band;
    V grad{};
    if (!sample(g, xr, phi, grad) && !g.container) return false;
    if (!(phi < -depth)) return false;
    const V vw = f < 0 ? V{} : frame_velocity(frames[f], xi);
    const Real len = std::sqrt(dot(grad, grad));
    if (phi > -g.band + g.pitch && len > 0) {
      const V nr = grad * (Real(1) / len);
      const V n = f < 0 ? nr : turn(frames[f], nr, false);
      xi = xi + n * (margin - phi);
      const Real vn = dot(vi - vw, n);
      if (vn < 0) vi = vi - n * vn;
    } else {
      xi = xi - vi * dt;
      vi = f < 0 ? V{} : frame_velocity(frames[f], xi);
    }
    return true;
  }

  // Solid k's signed distance at world point s (k = 0: the tank, then the boxes, then the grids), positive
  // on the fluid's side; where it is negative, also the solid's normal to the fluid side (world) and its
  // velocity there. Exact inside a box or the tank (the nearest face), a bound outside; +1 m where a solid
  // is absent.
  CELLSPH_HD Real solid_phi(std::size_t k, const V& s, V& n, V& vw) const {
    using namespace guard_detail;
    n = V{};
    vw = V{};
    if (k == 0) {
      if (!container) return Real(1);
      Real phi = Real(1e30);
      for (int a = 0; a < Dim; ++a) {
        if (s[a] - lo[a] < phi) {
          phi = s[a] - lo[a];
          n = V{};
          n[a] = 1;
        }
        if (a != open_axis && hi[a] - s[a] < phi) {
          phi = hi[a] - s[a];
          n = V{};
          n[a] = -1;
        }
      }
      return phi;
    }
    if (k - 1 < box_count) {
      const GuardBox<Dim, Real>& b = boxes[k - 1];
      const std::int32_t f = b.mover.frame(motions);
      const V sr = f < 0 ? s : to_rest(frames[f], s);
      Real inside = Real(1e30), outside = 0;
      V nr{};
      for (int a = 0; a < Dim; ++a) {
        const Real below = sr[a] - b.lo[a], above = b.hi[a] - sr[a];
        if (-below > outside) outside = -below;
        if (-above > outside) outside = -above;
        if (below < inside || above < inside) {
          nr = V{};
          nr[a] = below < above ? Real(-1) : Real(1);
          inside = below < above ? below : above;
        }
      }
      if (outside > 0) return outside;
      n = f < 0 ? nr : turn(frames[f], nr, false);
      if (f >= 0) vw = frame_velocity(frames[f], s);
      return -inside;
    }
    const GuardGrid<Dim, Real>& g = grids[k - 1 - box_count];
    const std::int32_t f = g.mover.frame(motions);
    const V sr = f < 0 ? s : to_rest(frames[f], s);
    Real phi = -g.band;
    V grad{};
    if (!sample(g, sr, phi, grad) && !g.container) return g.band;
    if (phi < 0) {
      const Real len = std::sqrt(dot(grad, grad));
      const V nr = len > 0 ? grad * (Real(1) / len) : V{};
      n = f < 0 ? nr : turn(frames[f], nr, false);
      if (f >= 0) vw = frame_velocity(frames[f], s);
    }
    return phi;
  }

  // A fast particle (one that moved more than `depth` in the step) followed from where it started, in
  // samples a quarter spacing apart, through each solid: its path is stopped where it first went deeper than
  // `depth` into one, or through one (in, deeper than `depth` / 2, and out again: a wall one spacing thick
  // is crossed so in a step). It stops at the last sample before it went in, its velocity into the solid
  // removed.
  CELLSPH_HD bool follow(V& xi, V& vi) const {
    using namespace guard_detail;
    if (!(dt > 0)) return false;
    const V d = vi * dt;
    const Real len = std::sqrt(dot(d, d));
    if (!(len > depth)) return false;
    Real steps = std::ceil(2 * len / depth);
    if (steps > Real(kMaxSweptSteps)) steps = Real(kMaxSweptSteps);
    const int last = static_cast<int>(steps);
    const V start = xi - d;
    int stop = last + 1, entry = 0;  // the earliest sample stopped at, and the sample before it went in
    V n_stop{}, vw_stop{};
    for (std::size_t k = 0; k < 1 + box_count + grid_count; ++k) {
      int before = 0;        // the last sample on the fluid side so far
      bool went_in = false;  // a sample on the solid's side after one on the fluid side
      Real deepest = 0;
      V n_in{}, vw_in{};
      for (int j = 0; j <= last && j < stop; ++j) {
        V n, vw;
        const Real phi = solid_phi(k, start + d * (Real(j) / steps), n, vw);
        if (phi >= 0) {
          if (went_in && deepest < -depth / 2) {  // through it
            stop = j;
            entry = before;
            n_stop = n_in;
            vw_stop = vw_in;
            break;
          }
          before = j;
          went_in = false;
          deepest = 0;
          continue;
        }
        if (!went_in) {
          n_in = n;
          vw_in = vw;
        }
        went_in = went_in || j > 0;
        if (phi < deepest) deepest = phi;
        if (phi < -depth && j > 0) {  // too deep
          stop = j;
          entry = went_in ? before : j - 1;
          n_stop = n;
          vw_stop = vw;
          break;
        }
      }
    }
    if (stop > last) return false;
    xi = start + d * (Real(entry) / steps);
    const Real vn = dot(vi - vw_stop, n_stop);
    if (vn < 0) vi = vi - n_stop * vn;
    return true;
  }
};

template <int Dim, class Real>
SolidGuardPass<Dim, Real> solid_guard(const SolidGuard<Dim, Real>& g, const ParticleView<Dim, Real>& pv,
                                      const GuardFrame* frames, std::int32_t motions, Real dt) {
  return {pv.x,
          pv.v,
          g.container,
          g.lo,
          g.hi,
          g.open_axis,
          g.boxes.data(),
          g.boxes.size(),
          g.grids.data(),
          g.grids.size(),
          g.grid_values.data(),
          frames,
          motions,
          g.depth,
          g.margin,
          dt};
}

}  // namespace cellsph
