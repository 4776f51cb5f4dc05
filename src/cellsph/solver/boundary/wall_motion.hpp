#pragma once
// Moving walls: prescribed motions of obstacles (scene key boundary.obstacles[k].motion, docs/scenes.md
// "Moving obstacles"). Everything about wall motion is here:
//  * WallMotion: one motion (translate, rotate, oscillate, or a table of displacements and angles
//    interpolated linearly), evaluated in double precision as a pure function of the time and the
//    particle's initial position: x(t) = c + d(t) + R(angle(t)) (x0 - c), its velocity and acceleration;
//  * WallMotions: the motions of a scene and, per particle (input order), which one moves it;
//  * MovingWallPass: each step sets the moving wall particles' positions, velocities and accelerations
//    from their initial positions and the clock (Simulation::move_walls). Nothing is integrated, so the
//    walls' state is the same bits for any thread count and after a resume (the initial positions come
//    from the scene, matched by particle id);
//  * parse_motion_table: the CSV table (time,x,y[,z][,angle]), strict, every error naming the file,
//    line, column and value.
// The boundary models read the walls' velocity (particles' v of a wall particle; 0 for walls at rest) in
// their no-slip and pressure terms, and Adami's pressure its acceleration (wall_a).
// In 2D, rotation is about the out-of-plane axis: a positive omega or angle turns x towards y.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"

namespace cellsph {

enum class MotionKind : std::uint8_t { Translate, Rotate, Oscillate, Table };

// One row of a motion table: time [s], displacement [m] (z = 0 in 2D), angle [degrees].
struct MotionTableRow {
  double t = 0;
  double d[3] = {0, 0, 0};
  double angle_deg = 0;
};

// One prescribed motion. Times in s, lengths in m, angles in rad (omega rad/s) except the table's
// angle column (degrees).
struct WallMotion {
  MotionKind kind = MotionKind::Translate;
  double velocity[3] = {0, 0, 0};   // translate [m/s]
  double start = 0;                 // translate, rotate: moving from this time [s]
  double end = HUGE_VAL;            // ... until this time (then at rest where it got to)
  double axis[3] = {0, 0, 1};       // rotate, table: unit axis (2D: the out-of-plane axis, z)
  double center[3] = {0, 0, 0};     // rotate, table: a point of the axis at t = 0 [m]
  double omega = 0;                 // rotate [rad/s], right hand about axis
  double direction[3] = {1, 0, 0};  // oscillate: unit direction
  double amplitude = 0;             // oscillate [m]
  double period = 1;                // oscillate [s]
  std::uint32_t table_begin = 0;    // table: rows table_begin .. table_end of WallMotions::rows
  std::uint32_t table_end = 0;
};

// The state of a moving point at a time: x, v, a (double precision, 3 components; z = 0 in 2D).
struct MotionState {
  double x[3], v[3], a[3];
};

namespace motion_detail {

CELLSPH_HD inline void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// r rotated by `angle` [rad] about unit axis k (Rodrigues).
CELLSPH_HD inline void rotate(const double* k, double angle, const double* r, double* out) {
  const double c = std::cos(angle), s = std::sin(angle);
  double kr[3];
  cross(k, r, kr);
  const double kd = k[0] * r[0] + k[1] * r[1] + k[2] * r[2];
  for (int a = 0; a < 3; ++a) out[a] = r[a] * c + kr[a] * s + k[a] * kd * (1 - c);
}

// Rigid motion: x = c + d + R(angle) (x0 - c), v = dv + w k x (x - c - d), a = dd_a + w k x (w k x r).
CELLSPH_HD inline void rigid(const double* x0, const double* c, const double* k, const double* d,
                             const double* dv, const double* da, double angle, double w, MotionState& s) {
  double r0[3], r[3], wr[3], wwr[3], wk[3];
  for (int a = 0; a < 3; ++a) r0[a] = x0[a] - c[a];
  rotate(k, angle, r0, r);
  for (int a = 0; a < 3; ++a) wk[a] = w * k[a];
  cross(wk, r, wr);
  cross(wk, wr, wwr);
  for (int a = 0; a < 3; ++a) {
    s.x[a] = c[a] + d[a] + r[a];
    s.v[a] = dv[a] + wr[a];
    s.a[a] = da[a] + wwr[a];
  }
}

}  // namespace motion_detail

// The state at time t of the wall point that was at x0 at t = 0 (x0 z = 0 in 2D). `rows`: the table rows
// of every motion (WallMotions::rows). Before a table's first time it holds the first row, after its last
// the last (at rest); between rows, displacement and angle are linear in t (velocity constant over each
// interval, acceleration 0 but for the rotation's centripetal part).
CELLSPH_HD inline MotionState evaluate_motion(const WallMotion& m, const MotionTableRow* rows, double t,
                                              const double* x0) {
  using motion_detail::rigid;
  MotionState s{};
  const double zero[3] = {0, 0, 0};
  switch (m.kind) {
    case MotionKind::Translate: {
      const double tau = std::min(std::max(t - m.start, 0.0), m.end - m.start);
      const bool moving = t >= m.start && t < m.end;
      double d[3], dv[3];
      for (int a = 0; a < 3; ++a) {
        d[a] = m.velocity[a] * tau;
        dv[a] = moving ? m.velocity[a] : 0.0;
      }
      rigid(x0, zero, m.axis, d, dv, zero, 0.0, 0.0, s);
      break;
    }
    case MotionKind::Rotate: {
      const double tau = std::min(std::max(t - m.start, 0.0), m.end - m.start);
      const bool moving = t >= m.start && t < m.end;
      rigid(x0, m.center, m.axis, zero, zero, zero, m.omega * tau, moving ? m.omega : 0.0, s);
      break;
    }
    case MotionKind::Oscillate: {
      const double w = 2 * 3.14159265358979323846 / m.period;
      const double sn = std::sin(w * t), cs = std::cos(w * t);
      double d[3], dv[3], da[3];
      for (int a = 0; a < 3; ++a) {
        d[a] = m.direction[a] * m.amplitude * sn;
        dv[a] = m.direction[a] * m.amplitude * w * cs;
        da[a] = -m.direction[a] * m.amplitude * w * w * sn;
      }
      rigid(x0, zero, m.axis, d, dv, da, 0.0, 0.0, s);
      break;
    }
    case MotionKind::Table: {
      const MotionTableRow* first = rows + m.table_begin;
      const MotionTableRow* last = rows + m.table_end - 1;  // at least one row
      constexpr double deg = 3.14159265358979323846 / 180;
      if (t <= first->t || first == last) {
        rigid(x0, m.center, m.axis, first->d, zero, zero, first->angle_deg * deg, 0.0, s);
      } else if (t >= last->t) {
        rigid(x0, m.center, m.axis, last->d, zero, zero, last->angle_deg * deg, 0.0, s);
      } else {
        // The interval [lo->t, (lo + 1)->t) holding t: binary search (times strictly increase).
        const MotionTableRow* lo = first;
        const MotionTableRow* hi = last;
        while (hi - lo > 1) {
          const MotionTableRow* mid = lo + (hi - lo) / 2;
          if (mid->t <= t)
            lo = mid;
          else
            hi = mid;
        }
        const double span = hi->t - lo->t, f = (t - lo->t) / span;
        double d[3], dv[3];
        for (int a = 0; a < 3; ++a) {
          d[a] = lo->d[a] + (hi->d[a] - lo->d[a]) * f;
          dv[a] = (hi->d[a] - lo->d[a]) / span;
        }
        const double angle = (lo->angle_deg + (hi->angle_deg - lo->angle_deg) * f) * deg;
        const double w = (hi->angle_deg - lo->angle_deg) * deg / span;
        rigid(x0, m.center, m.axis, d, dv, zero, angle, w, s);
      }
      break;
    }
  }
  return s;
}

// The motions of a scene (SolverConfig::wall_motion). of_particle: per particle in the input order (the
// order the Simulation is given them), the index of its motion in `motions`, or -1 (at rest); empty when
// nothing moves. Only boundary particles may move.
struct WallMotions {
  std::vector<WallMotion> motions;
  std::vector<MotionTableRow> rows;  // the tables' rows, each motion's a contiguous range
  std::vector<std::int32_t> of_particle;

  [[nodiscard]] bool any() const { return !motions.empty(); }
};

// Sets the moving wall particles' state at time t: k runs over the moving walls, slot[k] is the particle's
// index, x0[k] its initial position and motion[k] its motion. Writes x, v and wall_a of that particle.
template <int Dim, class Real>
struct MovingWallPass {
  using V = Vec<Dim, Real>;
  V* x;
  V* v;
  V* wall_a;
  const std::uint32_t* slot;
  const V* x0;
  const std::int32_t* motion;
  const WallMotion* motions;
  const MotionTableRow* rows;
  double t;

  CELLSPH_HD void operator()(std::size_t k) const {
    double p0[3] = {0, 0, 0};
    for (int a = 0; a < Dim; ++a) p0[a] = static_cast<double>(x0[k][a]);
    const MotionState s = evaluate_motion(motions[motion[k]], rows, t, p0);
    const std::uint32_t i = slot[k];
    for (int a = 0; a < Dim; ++a) {
      x[i][a] = static_cast<Real>(s.x[a]);
      v[i][a] = static_cast<Real>(s.v[a]);
      wall_a[i][a] = static_cast<Real>(s.a[a]);
    }
  }
};

// Parses a motion table: a header line naming the columns, `time,x,y` or `time,x,y,angle` in 2D,
// `time,x,y,z` or `time,x,y,z,angle` in 3D (spaces around commas allowed; lines starting with # and blank
// lines skipped), then one row of finite numbers per line with strictly increasing times. Appends the
// rows to `out`. Throws InputError "FILE line L, column C (NAME): what" on the first problem (`file` as
// the user named it).
void parse_motion_table(std::string_view text, const std::string& file, int dim,
                        std::vector<MotionTableRow>& out);

}  // namespace cellsph
