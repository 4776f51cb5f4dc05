#pragma once
// Floating rigid bodies with two-way coupling (Akinci et al. 2012, "Versatile rigid-fluid coupling for
// incompressible SPH"; scene key `bodies`, docs/scenes.md "Floating bodies", docs/physics.md). A body is
// a set of boundary particles (sampled like an obstacle) that moves rigidly: a moving wall whose motion
// is integrated from the fluid's force instead of prescribed. Everything about bodies is here:
//  * RigidBody / RigidBodies: the bodies of a scene (mass, inertia about the centre of mass, initial
//    state) and, per particle in the input order, which body it belongs to (SolverConfig::rigid_bodies);
//  * BodyReactionPass: per body particle b, the opposite of the force b exerts on each of its fluid
//    neighbours, from the WCSPH force pass's own wall_pair (models/wcsph.hpp: one expression for both);
//  * BodyContactPass: a spring-damper between a body particle and every boundary particle of another
//    wall or body closer than the contact distance (the body's only contact model);
//  * RigidBodySystem: the serial sums (force, torque: fixed order, so the same bits for any thread
//    count), the symplectic Euler step of each body (quaternion orientation, world inertia tensor), and
//    BodyPlacePass, which puts the body particles where the body is (x = X + R r0, v = V + w x r).
// Units: SI; in 2D masses are per metre of depth (density times area), as the fluid's.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/core/hd.hpp"
#include "cellsph/core/vec.hpp"
#include "cellsph/solver/particle_view.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// A body's state: centre of mass x [m], orientation q (unit quaternion w, x, y, z: body frame to world),
// velocity v [m/s], angular velocity w [rad/s] (world frame), and the last step's linear and angular
// accelerations (the walls' acceleration that Adami's wall pressure reads). z components 0 in 2D, where
// rotation is about z.
struct RigidBodyState {
  double x[3] = {0, 0, 0};
  double q[4] = {1, 0, 0, 0};
  double v[3] = {0, 0, 0};
  double w[3] = {0, 0, 0};
  double a[3] = {0, 0, 0};
  double alpha[3] = {0, 0, 0};
};

// One floating body: its mass [kg, 2D: kg/m], its inertia tensor about the centre of mass in the body
// frame (row major), and its state at t = 0. `shape` names what it was made from, for messages.
struct RigidBody {
  std::string shape;
  double density = 0;
  double mass = 0;
  double inertia[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  RigidBodyState initial;
};

// The bodies of a scene. of_particle: per particle in the input order, its body or -1 (empty when there
// are no bodies). Contact (BodyContactPass): body particles closer than contact_distance to another wall's
// or body's particle are pushed apart by a spring of angular frequency contact_frequency [rad/s] (0: the
// default, half the sound speed over the contact distance) with damping ratio contact_damping, per unit of
// the body's mass per particle.
struct RigidBodies {
  std::vector<RigidBody> bodies;
  std::vector<std::int32_t> of_particle;
  double contact_distance = 0;
  double contact_frequency = 0;
  double contact_damping = 1;

  [[nodiscard]] bool any() const { return !bodies.empty(); }
};

namespace body_detail {

CELLSPH_HD inline void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// r rotated by the unit quaternion q.
CELLSPH_HD inline void rotate(const double* q, const double* r, double* out) {
  // out = r + 2 w (u x r) + 2 u x (u x r), u = (q1, q2, q3)
  const double u[3] = {q[1], q[2], q[3]};
  double t[3], ut[3];
  cross(u, r, t);
  for (int a = 0; a < 3; ++a) t[a] *= 2;
  cross(u, t, ut);
  for (int a = 0; a < 3; ++a) out[a] = r[a] + q[0] * t[a] + ut[a];
}

}  // namespace body_detail

// Per body particle k (slot[k]): minus the sum over its fluid neighbours i of the force i feels from it,
// forces.wall_pair: the pressure and viscous terms of the wall model in use, the same expression the
// fluid's pass added. The neighbours: b's own candidate row (body particles are searched at h + skin)
// cut with the fluid rows' own test, |x_i - x_b|^2 <= h_i^2 (verlet_rows.hpp), so exactly the pairs the
// fluid's pass saw, in ascending i.
template <int Dim, class Real, class ForcesPass>
struct BodyReactionPass {
  ParticleView<Dim, Real> pv;
  ForcesPass forces;
  const std::uint32_t* slot;
  Vec<Dim, double>* out;

  CELLSPH_HD void operator()(std::size_t k) const {
    using V = Vec<Dim, Real>;
    const std::uint32_t b = slot[k];
    Vec<Dim, double> s{};
    for (const auto* it = pv.candidates_begin(b); it != pv.candidates_end(b); ++it) {
      const std::uint32_t i = *it;
      if (!pv.is_fluid(i) || !(distance2(pv.x[i], pv.x[b]) <= pv.h[i] * pv.h[i])) continue;
      const V xib = pv.x[i] - pv.x[b];
      const Real r = norm(xib);
      const V g = forces.wg.gradW(xib);
      V fp{}, fnp{};
      forces.wall_pair(i, b, xib, r, g, fp, fnp);
      for (int a = 0; a < Dim; ++a) s[a] -= static_cast<double>(fp[a]) + static_cast<double>(fnp[a]);
    }
    out[k] = s;
  }
};

// Per body particle k (slot[k], of body body_of_slot[slot[k]]): the contact force from every boundary
// particle c of another body or of a wall within d0 (its candidate rows, searched at d0 + skin): along
// n = (x_b - x_c) / |x_b - x_c|, m (w^2 (d0 - r) - 2 zeta w (v_b - v_c) . n), never pulling; m is the
// body's mass per particle (against a body: the two bodies' reduced). Added to out[k].
template <int Dim, class Real>
struct BodyContactPass {
  ParticleView<Dim, Real> pv;
  const std::uint32_t* slot;
  const std::int32_t* body_of_slot;  // per particle: its body or -1
  const double* mass_per_particle;   // per body
  double d0, w2, c;                  // contact distance, w^2, 2 zeta w
  Vec<Dim, double>* out;

  CELLSPH_HD void operator()(std::size_t k) const {
    const std::uint32_t b = slot[k];
    const std::int32_t body = body_of_slot[b];
    const double mb = mass_per_particle[body];
    Vec<Dim, double> s{};
    for (const auto* it = pv.candidates_begin(b); it != pv.candidates_end(b); ++it) {
      const std::uint32_t o = *it;
      if (pv.kind[o] != pv.kBoundary || body_of_slot[o] == body) continue;
      double d[3] = {0, 0, 0}, dv[3] = {0, 0, 0}, r2 = 0;
      for (int a = 0; a < Dim; ++a) {
        d[a] = static_cast<double>(pv.x[b][a]) - static_cast<double>(pv.x[o][a]);
        dv[a] = static_cast<double>(pv.v[b][a]) - static_cast<double>(pv.v[o][a]);
        r2 += d[a] * d[a];
      }
      if (!(r2 < d0 * d0) || r2 == 0) continue;
      const double r = std::sqrt(r2);
      double vn = 0;
      for (int a = 0; a < Dim; ++a) vn += dv[a] * d[a] / r;
      double m = mb;
      if (body_of_slot[o] >= 0) {
        const double mo = mass_per_particle[body_of_slot[o]];
        m = mb * mo / (mb + mo);
      }
      const double f = m * (w2 * (d0 - r) - c * vn);
      if (f > 0)
        for (int a = 0; a < Dim; ++a) s[a] += f * d[a] / r;
    }
    out[k] += s;
  }
};

// Puts each body particle k (slot[k], body body[k], body-frame offset r0[k] from the centre of mass)
// where its body is: x = X + R(q) r0, v = V + w x r, wall acceleration A + alpha x r + w x (w x r).
template <int Dim, class Real>
struct BodyPlacePass {
  Vec<Dim, Real>* x;
  Vec<Dim, Real>* v;
  Vec<Dim, Real>* wall_a;  // may be null
  const std::uint32_t* slot;
  const std::int32_t* body;
  const std::array<double, 3>* r0;
  const RigidBodyState* states;

  CELLSPH_HD void operator()(std::size_t k) const {
    using body_detail::cross;
    const RigidBodyState& s = states[body[k]];
    double r[3], wr[3], wwr[3], ar[3];
    body_detail::rotate(s.q, r0[k].data(), r);
    cross(s.w, r, wr);
    cross(s.w, wr, wwr);
    cross(s.alpha, r, ar);
    const std::uint32_t i = slot[k];
    for (int a = 0; a < Dim; ++a) {
      x[i][a] = static_cast<Real>(s.x[a] + r[a]);
      v[i][a] = static_cast<Real>(s.v[a] + wr[a]);
      if (wall_a) wall_a[i][a] = static_cast<Real>(s.a[a] + ar[a] + wwr[a]);
    }
  }
};

// The force [N] and torque [N m] (about the centre of mass) on a body in the last step, fluid and
// contact together (gravity not included).
struct RigidBodyLoad {
  double force[3] = {0, 0, 0};
  double torque[3] = {0, 0, 0};
};

// The bodies of a Simulation: their slots among the particles, states and loads. Host code; the passes
// above are CELLSPH_HD.
template <int Dim, class Real>
class RigidBodySystem {
 public:
  using V = Vec<Dim, Real>;

  [[nodiscard]] bool any() const { return !states_.empty(); }
  [[nodiscard]] const std::vector<RigidBodyState>& states() const { return states_; }
  [[nodiscard]] const std::vector<RigidBodyLoad>& loads() const { return loads_; }
  [[nodiscard]] const std::vector<std::uint32_t>& slots() const { return slot_; }

  // From the particles given to the Simulation (input order, ids assigned): each body particle's offset
  // from its body's centre at t = 0, kept by id. Throws InputError when a fluid particle is given a body.
  // `sound_speed`: the fluid's, for the default contact frequency.
  void init(const RigidBodies& cfg, const std::vector<V>& x, const std::vector<std::uint8_t>& kind,
            const std::vector<std::uint32_t>& id, double sound_speed);
  // The contact spring's angular frequency in use [rad/s].
  [[nodiscard]] double contact_frequency() const { return frequency_; }
  // The slots of the body particles (ascending among `boundary`), from the particles' ids. `owned` (a run
  // across ranks: per slot, 1 for a particle this rank owns): slots() only the owned ones, body_of_slot()
  // every body particle of `boundary` (the contact pass tells a halo copy's body from a wall).
  void set_slots(const std::vector<std::uint32_t>& id, const std::vector<std::uint32_t>& boundary,
                 std::size_t n, const std::vector<std::uint8_t>* owned = nullptr);
  // Replaces the states (a checkpoint's); InputError naming `source` when there are not as many as bodies
  // or one is not finite or its quaternion not of unit length.
  void set_states(std::vector<RigidBodyState> states, const std::string& source);
  // Each body particle's reaction force and contact force, summed per body in slot order (loads()), from
  // the body particles' candidate rows; `forces`: the WCSPH force pass.
  template <class ForcesPass>
  void compute_loads(const ParticleView<Dim, Real>& pv, const ForcesPass& forces);
  // The same sums from forces computed elsewhere (a device): per body particle k its force f[k] (the two
  // passes' sum) and its position x[k].
  void sum_loads(const std::vector<Vec<Dim, double>>& f, const std::vector<V>& x) {
    f_ = f;
    add_loads(
        f_.size(), [&](std::size_t k) { return body_[k]; }, [&](std::size_t k) { return x[k]; });
  }
  // The same sums over lists given whole (a run across ranks: every rank's body particles, in id order):
  // per body particle its body, force and position.
  void sum_loads_of(const std::vector<std::int32_t>& body, const std::vector<Vec<Dim, double>>& f,
                    const std::vector<V>& x) {
    f_ = f;
    add_loads(
        f_.size(), [&](std::size_t k) { return body[k]; }, [&](std::size_t k) { return x[k]; });
  }
  // Per body particle of slots(), the force of the last compute_loads.
  [[nodiscard]] const std::vector<Vec<Dim, double>>& forces() const { return f_; }
  // The contact pass over the body particles slot[k] with this system's constants, over the given arrays
  // (host or device: slot, body_of_slot, mass_per_particle as those below).
  [[nodiscard]] BodyContactPass<Dim, Real> contact_pass(const ParticleView<Dim, Real>& pv,
                                                        const std::uint32_t* slot,
                                                        const std::int32_t* body_of_slot,
                                                        const double* mass_per_particle,
                                                        Vec<Dim, double>* out) const {
    const double w = frequency_;
    return {pv,
            slot,
            body_of_slot,
            mass_per_particle,
            cfg_->contact_distance,
            w * w,
            2 * cfg_->contact_damping * w,
            out};
  }
  // Per body particle k its body and its offset in the body frame; per body its mass per particle.
  [[nodiscard]] const std::vector<std::int32_t>& body_of_body_particle() const { return body_; }
  [[nodiscard]] const std::vector<std::array<double, 3>>& offsets() const { return r0_; }
  [[nodiscard]] const std::vector<double>& mass_per_particle() const { return mass_per_particle_; }
  // One symplectic Euler step of dt under gravity g and loads().
  void advance(double dt, const V& g);
  // The body particles where the bodies are (BodyPlacePass).
  void place(std::vector<V>& x, std::vector<V>& v, std::vector<V>& wall_a) const;
  // Per particle slot, its body or -1 (n entries once set_slots ran).
  [[nodiscard]] const std::vector<std::int32_t>& body_of_slot() const { return body_of_slot_; }
  // Total momentum of the bodies (M V).
  [[nodiscard]] std::array<double, 3> momentum() const;

 private:
  // loads() from f_ and the body particles' bodies body_of(k) and positions x_of(k), k < count, serially
  // in k's order.
  template <class BodyOf, class PositionOf>
  void add_loads(std::size_t count, const BodyOf& body_of, const PositionOf& x_of);

  const RigidBodies* cfg_ = nullptr;
  double frequency_ = 0;
  std::vector<std::int32_t> body_of_id_;
  std::vector<std::array<double, 3>> r0_of_id_;
  std::vector<std::uint32_t> slot_;  // per body particle k
  std::vector<std::int32_t> body_;
  std::vector<std::array<double, 3>> r0_;
  std::vector<std::int32_t> body_of_slot_;
  std::vector<double> mass_per_particle_;
  std::vector<RigidBodyState> states_;
  std::vector<RigidBodyLoad> loads_;
  std::vector<Vec<Dim, double>> f_;  // per body particle, the last step's force
};

// Mass and inertia tensor (body frame = world axes at t = 0, about the centre) of a solid box of
// `density` with edges `size` (Dim of them) and of a ball (a disc in 2D) of `radius`. 2D: per metre of
// depth, rotation about z.
void box_mass_properties(int dim, double density, const double* size, RigidBody& out);
void ball_mass_properties(int dim, double density, double radius, RigidBody& out);
// Of a solid given by lattice points (cells of edge `spacing`, Dim of them): mass and inertia summed over
// the cells, each a point mass plus its own cell's inertia; `center` receives the centre of mass.
void lattice_mass_properties(int dim, double density, double spacing,
                             const std::vector<std::array<double, 3>>& pts, RigidBody& out, double* center);

template <int Dim, class Real>
template <class ForcesPass>
void RigidBodySystem<Dim, Real>::compute_loads(const ParticleView<Dim, Real>& pv, const ForcesPass& forces) {
  f_.resize(slot_.size());
  // Per particle in parallel (each writes its own entry), then summed serially in slot order: the same
  // bits for any thread count.
  run_pass(slot_.size(), BodyReactionPass<Dim, Real, ForcesPass>{pv, forces, slot_.data(), f_.data()});
  run_pass(slot_.size(),
           contact_pass(pv, slot_.data(), body_of_slot_.data(), mass_per_particle_.data(), f_.data()));
  add_loads(
      slot_.size(), [&](std::size_t k) { return body_[k]; }, [&](std::size_t k) { return pv.x[slot_[k]]; });
}

template <int Dim, class Real>
template <class BodyOf, class PositionOf>
void RigidBodySystem<Dim, Real>::add_loads(std::size_t count, const BodyOf& body_of, const PositionOf& x_of) {
  loads_.assign(states_.size(), RigidBodyLoad{});
  for (std::size_t k = 0; k < count; ++k) {
    const auto b = static_cast<std::size_t>(body_of(k));
    RigidBodyLoad& l = loads_[b];
    const RigidBodyState& s = states_[b];
    double f[3] = {0, 0, 0}, r[3] = {0, 0, 0}, t[3];
    for (int a = 0; a < Dim; ++a) {
      f[a] = f_[k][a];
      r[a] = static_cast<double>(x_of(k)[a]) - s.x[a];
    }
    body_detail::cross(r, f, t);
    for (int a = 0; a < 3; ++a) {
      l.force[a] += f[a];
      l.torque[a] += t[a];
    }
  }
}

}  // namespace cellsph
