#include "cellsph/solver/boundary/rigid_bodies.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

namespace {

// out = A b for a row-major 3x3 A.
void mul(const double* A, const double* b, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = A[3 * r] * b[0] + A[3 * r + 1] * b[1] + A[3 * r + 2] * b[2];
}

// The rotation matrix of the unit quaternion q (row major).
void rotation_matrix(const double* q, double* R) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0] = 1 - 2 * (y * y + z * z);
  R[1] = 2 * (x * y - w * z);
  R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z);
  R[4] = 1 - 2 * (x * x + z * z);
  R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y);
  R[7] = 2 * (y * z + w * x);
  R[8] = 1 - 2 * (x * x + y * y);
}

// The inverse of a symmetric positive definite 3x3 matrix (cofactors); false when singular.
bool invert(const double* A, double* out) {
  const double c00 = A[4] * A[8] - A[5] * A[7], c01 = A[5] * A[6] - A[3] * A[8],
               c02 = A[3] * A[7] - A[4] * A[6];
  const double det = A[0] * c00 + A[1] * c01 + A[2] * c02;
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
  const double inv = 1 / det;
  out[0] = c00 * inv;
  out[1] = (A[2] * A[7] - A[1] * A[8]) * inv;
  out[2] = (A[1] * A[5] - A[2] * A[4]) * inv;
  out[3] = c01 * inv;
  out[4] = (A[0] * A[8] - A[2] * A[6]) * inv;
  out[5] = (A[2] * A[3] - A[0] * A[5]) * inv;
  out[6] = c02 * inv;
  out[7] = (A[1] * A[6] - A[0] * A[7]) * inv;
  out[8] = (A[0] * A[4] - A[1] * A[3]) * inv;
  return true;
}

}  // namespace

template <int Dim, class Real>
void RigidBodySystem<Dim, Real>::init(const RigidBodies& cfg, const std::vector<V>& x,
                                      const std::vector<std::uint8_t>& kind,
                                      const std::vector<std::uint32_t>& id, double sound_speed) {
  cfg_ = &cfg;
  states_.clear();
  if (!cfg.any()) return;
  const std::size_t n = x.size();
  if (cfg.of_particle.size() != n)
    throw InputError("particles: the bodies name " + std::to_string(cfg.of_particle.size()) +
                     " particles, there are " + std::to_string(n));
  frequency_ = cfg.contact_frequency > 0 ? cfg.contact_frequency : 0.5 * sound_speed / cfg.contact_distance;
  body_of_id_.assign(n, -1);
  r0_of_id_.assign(n, {0, 0, 0});
  std::vector<double> count(cfg.bodies.size(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t b = cfg.of_particle[i];
    if (b < 0) continue;
    if (kind[i] != static_cast<std::uint8_t>(ParticleKind::Boundary))
      throw InputError("particles: fluid particle " + std::to_string(i) + " is given to body " +
                       std::to_string(b));
    const RigidBodyState& s0 = cfg.bodies[static_cast<std::size_t>(b)].initial;
    // The offset in the body frame: R(q0)^T (x - X0).
    double d[3] = {0, 0, 0}, R[9], r[3] = {0, 0, 0};
    for (int a = 0; a < Dim; ++a) d[a] = static_cast<double>(x[i][a]) - s0.x[a];
    rotation_matrix(s0.q, R);
    for (int a = 0; a < 3; ++a) r[a] = R[a] * d[0] + R[3 + a] * d[1] + R[6 + a] * d[2];
    body_of_id_[id[i]] = b;
    r0_of_id_[id[i]] = {r[0], r[1], r[2]};
    count[static_cast<std::size_t>(b)] += 1;
  }
  mass_per_particle_.assign(cfg.bodies.size(), 0);
  for (std::size_t b = 0; b < cfg.bodies.size(); ++b) {
    if (count[b] == 0) throw InputError("bodies[" + std::to_string(b) + "]: has no boundary particles");
    mass_per_particle_[b] = cfg.bodies[b].mass / count[b];
    states_.push_back(cfg.bodies[b].initial);
  }
  loads_.assign(states_.size(), RigidBodyLoad{});
}

template <int Dim, class Real>
void RigidBodySystem<Dim, Real>::set_slots(const std::vector<std::uint32_t>& id,
                                           const std::vector<std::uint32_t>& boundary, std::size_t n,
                                           const std::vector<std::uint8_t>* owned) {
  slot_.clear();
  body_.clear();
  r0_.clear();
  body_of_slot_.assign(n, -1);
  if (!any()) return;
  for (const std::uint32_t b : boundary) {
    const std::int32_t body = body_of_id_[id[b]];
    if (body < 0) continue;
    body_of_slot_[b] = body;
    if (owned && !(*owned)[b]) continue;
    slot_.push_back(b);
    body_.push_back(body);
    r0_.push_back(r0_of_id_[id[b]]);
  }
}

template <int Dim, class Real>
void RigidBodySystem<Dim, Real>::set_states(std::vector<RigidBodyState> states, const std::string& source) {
  if (states.size() != states_.size())
    throw InputError(source + ": holds the state of " + std::to_string(states.size()) +
                     " bodies, the scene has " + std::to_string(states_.size()));
  for (std::size_t b = 0; b < states.size(); ++b) {
    const RigidBodyState& s = states[b];
    bool finite = true;
    for (const double* f : {s.x, s.v, s.w, s.a, s.alpha})
      for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(f[a]);
    double qq = 0;
    for (int a = 0; a < 4; ++a) {
      finite = finite && std::isfinite(s.q[a]);
      qq += s.q[a] * s.q[a];
    }
    if (!finite || std::abs(qq - 1) > 1e-6)
      throw InputError(source + ": body " + std::to_string(b) +
                       " has a non-finite state or an orientation that is not a unit quaternion");
  }
  states_ = std::move(states);
}

template <int Dim, class Real>
void RigidBodySystem<Dim, Real>::advance(double dt, const V& g) {
  for (std::size_t b = 0; b < states_.size(); ++b) {
    RigidBodyState& s = states_[b];
    const RigidBody& body = cfg_->bodies[b];
    const RigidBodyLoad& l = loads_[b];
    // Linear: V += dt (F / M + g), X += dt V (symplectic Euler, as the fluid in WCSPH).
    for (int a = 0; a < 3; ++a) {
      s.a[a] = l.force[a] / body.mass + (a < Dim ? static_cast<double>(g[a]) : 0.0);
      s.v[a] += dt * s.a[a];
      s.x[a] += dt * s.v[a];
    }
    // Angular: world inertia I = R I_b R^T; w += dt I^-1 (tau - w x I w); then q turned by the exact
    // rotation of w dt (in 2D w is along z, the gyroscopic term 0, and the angle exact).
    double R[9], Ib_R_T[9], I[9], Iinv[9];
    rotation_matrix(s.q, R);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        double acc = 0;
        for (int k = 0; k < 3; ++k) acc += body.inertia[3 * r + k] * R[3 * c + k];
        Ib_R_T[3 * r + c] = acc;
      }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        double acc = 0;
        for (int k = 0; k < 3; ++k) acc += R[3 * r + k] * Ib_R_T[3 * k + c];
        I[3 * r + c] = acc;
      }
    double tau[3] = {l.torque[0], l.torque[1], l.torque[2]};
    if (Dim == 2) tau[0] = tau[1] = 0;
    double Iw[3], gyro[3], rhs[3];
    mul(I, s.w, Iw);
    body_detail::cross(s.w, Iw, gyro);
    for (int a = 0; a < 3; ++a) rhs[a] = tau[a] - gyro[a];
    if (Dim == 2) {
      s.alpha[0] = s.alpha[1] = 0;
      s.alpha[2] = rhs[2] / I[8];
    } else {
      if (!invert(I, Iinv))
        Iinv[0] = Iinv[1] = Iinv[2] = Iinv[3] = Iinv[4] = Iinv[5] = Iinv[6] = Iinv[7] = Iinv[8] = 0;
      mul(Iinv, rhs, s.alpha);
    }
    for (int a = 0; a < 3; ++a) s.w[a] += dt * s.alpha[a];
    const double wn = std::sqrt(s.w[0] * s.w[0] + s.w[1] * s.w[1] + s.w[2] * s.w[2]);
    if (wn > 0) {
      const double half = 0.5 * wn * dt, sn = std::sin(half) / wn;
      const double dq[4] = {std::cos(half), s.w[0] * sn, s.w[1] * sn, s.w[2] * sn};
      const double* q = s.q;
      double nq[4] = {dq[0] * q[0] - dq[1] * q[1] - dq[2] * q[2] - dq[3] * q[3],
                      dq[0] * q[1] + dq[1] * q[0] + dq[2] * q[3] - dq[3] * q[2],
                      dq[0] * q[2] - dq[1] * q[3] + dq[2] * q[0] + dq[3] * q[1],
                      dq[0] * q[3] + dq[1] * q[2] - dq[2] * q[1] + dq[3] * q[0]};
      const double len = std::sqrt(nq[0] * nq[0] + nq[1] * nq[1] + nq[2] * nq[2] + nq[3] * nq[3]);
      for (int a = 0; a < 4; ++a) s.q[a] = nq[a] / len;
    }
  }
}

template <int Dim, class Real>
void RigidBodySystem<Dim, Real>::place(std::vector<V>& x, std::vector<V>& v, std::vector<V>& wall_a) const {
  if (slot_.empty()) return;
  run_pass(slot_.size(),
           BodyPlacePass<Dim, Real>{x.data(), v.data(), wall_a.empty() ? nullptr : wall_a.data(),
                                    slot_.data(), body_.data(), r0_.data(), states_.data()});
}

template <int Dim, class Real>
std::array<double, 3> RigidBodySystem<Dim, Real>::momentum() const {
  std::array<double, 3> p{0, 0, 0};
  for (std::size_t b = 0; b < states_.size(); ++b)
    for (int a = 0; a < 3; ++a) p[static_cast<std::size_t>(a)] += cfg_->bodies[b].mass * states_[b].v[a];
  return p;
}

void box_mass_properties(int dim, double density, const double* size, RigidBody& out) {
  const double a = size[0], b = size[1], c = dim == 3 ? size[2] : 0;
  out.mass = density * a * b * (dim == 3 ? c : 1);
  for (double& e : out.inertia) e = 0;
  const double m = out.mass / 12;
  if (dim == 2) {
    out.inertia[0] = m * b * b;
    out.inertia[4] = m * a * a;
    out.inertia[8] = m * (a * a + b * b);
  } else {
    out.inertia[0] = m * (b * b + c * c);
    out.inertia[4] = m * (a * a + c * c);
    out.inertia[8] = m * (a * a + b * b);
  }
}

void ball_mass_properties(int dim, double density, double radius, RigidBody& out) {
  const double pi = 3.14159265358979323846, r2 = radius * radius;
  for (double& e : out.inertia) e = 0;
  if (dim == 2) {
    out.mass = density * pi * r2;
    out.inertia[0] = out.inertia[4] = out.mass * r2 / 4;
    out.inertia[8] = out.mass * r2 / 2;
  } else {
    out.mass = density * 4 * pi * r2 * radius / 3;
    out.inertia[0] = out.inertia[4] = out.inertia[8] = 0.4 * out.mass * r2;
  }
}

void lattice_mass_properties(int dim, double density, double spacing,
                             const std::vector<std::array<double, 3>>& pts, RigidBody& out, double* center) {
  const double cell = dim == 3 ? spacing * spacing * spacing : spacing * spacing;
  const double m = density * cell;
  double c[3] = {0, 0, 0};
  for (const auto& p : pts)
    for (int a = 0; a < 3; ++a) c[a] += p[static_cast<std::size_t>(a)];
  for (int a = 0; a < 3; ++a) c[a] = pts.empty() ? 0 : c[a] / double(pts.size());
  out.mass = m * double(pts.size());
  for (double& e : out.inertia) e = 0;
  for (const auto& p : pts) {
    const double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) out.inertia[3 * r + k] += m * ((r == k ? d2 : 0) - d[r] * d[k]);
  }
  // Each cell's own inertia about its centre (a cube of edge `spacing`: m s^2 / 6 on the diagonal).
  for (int a = 0; a < 3; ++a) out.inertia[4 * a] += out.mass * spacing * spacing / 6;
  for (int a = 0; a < 3; ++a) center[a] = c[a];
}

template class RigidBodySystem<2, float>;
template class RigidBodySystem<2, double>;
template class RigidBodySystem<3, float>;
template class RigidBodySystem<3, double>;

}  // namespace cellsph
