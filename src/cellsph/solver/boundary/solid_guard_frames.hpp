#pragma once
// Where the solid guard's moving solids are at a time (boundary/solid_guard.hpp, GuardFrame): each
// prescribed motion's rigid transform at time t, then each floating body's from its state. Host only;
// the device stepper uploads them.
#include <cmath>
#include <cstdint>
#include <vector>

#include "cellsph/solver/boundary/rigid_bodies.hpp"
#include "cellsph/solver/boundary/wall_motion.hpp"
#include "cellsph/solver/config.hpp"

namespace cellsph {

// Motion m's transform at t: the images of the origin and the unit axes give R and b, their velocities
// the angular velocity (W = V R^T, V's columns the axes' velocities less the origin's).
inline GuardFrame motion_frame(const WallMotion& m, const MotionTableRow* rows, double t) {
  GuardFrame f;
  const double origin[3] = {0, 0, 0};
  const MotionState o = evaluate_motion(m, rows, t, origin);
  double vel[9];  // column k: the velocity of axis k's image less the origin's
  for (int k = 0; k < 3; ++k) {
    double e[3] = {0, 0, 0};
    e[k] = 1;
    const MotionState s = evaluate_motion(m, rows, t, e);
    for (int a = 0; a < 3; ++a) {
      f.R[3 * a + k] = s.x[a] - o.x[a];
      vel[3 * a + k] = s.v[a] - o.v[a];
    }
  }
  double W[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) W[3 * r + c] += vel[3 * r + k] * f.R[3 * c + k];
  for (int a = 0; a < 3; ++a) {
    f.b[a] = o.x[a];
    f.c[a] = o.x[a];
    f.u[a] = o.v[a];
  }
  f.w[0] = W[7];
  f.w[1] = W[2];
  f.w[2] = W[3];
  return f;
}

// Where a body in state s will be after a step of dt if it keeps its velocity and angular velocity (the
// step's forces move it after the guard has run; the difference is of order dt^2): x = X' + R' (x_rest -
// x0), with x0 where the scene placed it (orientation 1 there), X' = X + v dt, R' = R(w dt) R(q).
inline GuardFrame body_frame(const RigidBodyState& s, const double* x0, double dt) {
  GuardFrame f;
  const double wn = std::sqrt(s.w[0] * s.w[0] + s.w[1] * s.w[1] + s.w[2] * s.w[2]);
  const double axis[3] = {wn > 0 ? s.w[0] / wn : 0, wn > 0 ? s.w[1] / wn : 0, wn > 0 ? s.w[2] / wn : 1};
  for (int k = 0; k < 3; ++k) {
    double e[3] = {0, 0, 0}, r[3], r1[3];
    e[k] = 1;
    body_detail::rotate(s.q, e, r);
    motion_detail::rotate(axis, wn * dt, r, r1);
    for (int a = 0; a < 3; ++a) f.R[3 * a + k] = r1[a];
  }
  for (int a = 0; a < 3; ++a) {
    double rx0 = 0;
    for (int k = 0; k < 3; ++k) rx0 += f.R[3 * a + k] * x0[k];
    f.c[a] = s.x[a] + s.v[a] * dt;
    f.b[a] = f.c[a] - rx0;
    f.u[a] = s.v[a];
    f.w[a] = s.w[a];
  }
  return f;
}

// The frames of every moving solid at the end of a step of dt to time t: the motions' at t, then the
// bodies' (`states` at the step's start, in the order of cfg.rigid_bodies.bodies; empty without bodies).
template <int Dim, class Real>
std::vector<GuardFrame> guard_frames(const SolverConfig<Dim, Real>& cfg, double t, double dt,
                                     const std::vector<RigidBodyState>& states) {
  std::vector<GuardFrame> out;
  const auto& wm = cfg.wall_motion;
  for (const auto& m : wm.motions) out.push_back(motion_frame(m, wm.rows.data(), t));
  for (std::size_t k = 0; k < states.size() && k < cfg.rigid_bodies.bodies.size(); ++k)
    out.push_back(body_frame(states[k], cfg.rigid_bodies.bodies[k].initial.x, dt));
  return out;
}

}  // namespace cellsph
