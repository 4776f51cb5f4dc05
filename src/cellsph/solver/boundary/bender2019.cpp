// Building the volume map (boundary/bender2019.hpp): the solids' distance and the differences of D,
// grad D and F from the planar profile, node by node; and the profile itself.
#include "cellsph/solver/boundary/bender2019.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"

namespace cellsph {

namespace {

using P = std::array<double, 3>;

// The solids of a SolidGuard but its tank (boxes, shapes) in double precision: the distance to the
// nearest, positive on the fluid side.
template <int Dim, class Real>
class Solids {
 public:
  Solids(const SolidGuard<Dim, Real>& g, double reach) : g_(g), reach_(reach) {}
  [[nodiscard]] double reach() const { return reach_; }

  [[nodiscard]] static double box(const GuardBox<Dim, Real>& b, const P& y) {
    double out2 = 0, in = -std::numeric_limits<double>::infinity();
    for (int a = 0; a < Dim; ++a) {
      const double o = std::max(double(b.lo[a]) - y[a], y[a] - double(b.hi[a]));
      if (o > 0) out2 += o * o;
      in = std::max(in, o);
    }
    return out2 > 0 ? std::sqrt(out2) : in;
  }
  // A shaped solid's grid, interpolated (off the grid: outside a solid, deep in a container's wall).
  [[nodiscard]] double grid(const GuardGrid<Dim, Real>& gr, const P& y) const {
    std::int64_t base[3] = {0, 0, 0};
    double frac[3] = {0, 0, 0};
    for (int a = 0; a < Dim; ++a) {
      const double u = (y[a] - double(gr.origin[a])) / double(gr.pitch);
      if (!(u >= 0 && u <= double(gr.n[a] - 1))) return gr.container ? -double(gr.band) : double(gr.band);
      base[a] = std::min<std::int64_t>(static_cast<std::int64_t>(u), gr.n[a] - 2);
      frac[a] = u - double(base[a]);
    }
    double s = 0;
    for (int c = 0; c < (1 << Dim); ++c) {
      double w = 1;
      std::int64_t idx = 0, stride = 1;
      for (int a = 0; a < Dim; ++a) {
        const int bit = (c >> a) & 1;
        w *= bit ? frac[a] : 1 - frac[a];
        idx += stride * (base[a] + bit);
        stride *= gr.n[a];
      }
      s += w * double(g_.grid_values[gr.first + static_cast<std::uint64_t>(idx)]);
    }
    return s;
  }
  [[nodiscard]] double distance(const P& y) const {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& b : g_.boxes) d = std::min(d, box(b, y));
    for (const auto& gr : g_.grids) d = std::min(d, grid(gr, y));
    return d;
  }

 private:
  const SolidGuard<Dim, Real>& g_;
  double reach_;
};

// One voxel of the quadrature about a node: its centre's offset u and the integrals over it of W(|u|),
// of grad_x W(x - y) = -grad W(u) and of the ball's indicator over the ball's volume.
struct Voxel {
  P u{};
  double w = 0;
  P g{};
  double f = 0;
};

template <int Dim, class Kernel>
std::vector<Voxel> quadrature_voxels(const Kernel& w, double h, double q) {
  const int K = static_cast<int>(std::ceil(h / q));
  constexpr int kSub = 6;  // midpoint samples per axis inside a voxel
  const double ball = Dim == 3 ? 4.0 / 3.0 * M_PI * h * h * h : M_PI * h * h;
  const double dv = std::pow(q / kSub, Dim);
  std::vector<Voxel> out;
  const int kz = Dim == 3 ? K : 0;  // 2D: the one layer k = 0
  for (int k = -kz; k < std::max(kz, 1); ++k)
    for (int j = -K; j < K; ++j)
      for (int i = -K; i < K; ++i) {
        Voxel v;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < Dim; ++a) v.u[a] = (idx[a] + 0.5) * q;
        const int sz = Dim == 3 ? kSub : 1;
        for (int c = 0; c < sz; ++c)
          for (int b = 0; b < kSub; ++b)
            for (int a = 0; a < kSub; ++a) {
              const int s[3] = {a, b, c};
              Vec<Dim, double> x;
              for (int d = 0; d < Dim; ++d) x[d] = v.u[d] - q / 2 + (s[d] + 0.5) * q / kSub;
              const double r = norm(x);
              if (r > h) continue;
              v.w += w.W(r) * dv;
              const auto g = w.gradW(x);
              for (int d = 0; d < Dim; ++d) v.g[d] -= g[d] * dv;
              v.f += dv / ball;
            }
        if (v.f > 0) out.push_back(v);
      }
  return out;
}

// The differences of D, grad D and F at a node (distance phi, unit normal n) from the half-space's.
template <int Dim, class Real>
void node_corrections(const Solids<Dim, Real>& solids, const std::vector<Voxel>& voxels, double q, const P& x,
                      double phi, const P& n, double* out) {
  double cD = 0, cF = 0;
  P cG{};
  for (const Voxel& v : voxels) {
    P y{};
    double along = 0;
    for (int a = 0; a < Dim; ++a) {
      y[a] = x[a] + v.u[a];
      along += n[a] * v.u[a];
    }
    const double solid = std::clamp(0.5 - solids.distance(y) / q, 0.0, 1.0);
    const double plane = std::clamp(0.5 - (phi + along) / q, 0.0, 1.0);
    const double d = solid - plane;
    if (d == 0) continue;
    cD += d * v.w;
    cF += d * v.f;
    for (int a = 0; a < Dim; ++a) cG[a] += d * v.g[a];
  }
  out[0] = cD;
  for (int a = 0; a < Dim; ++a) out[1 + a] = cG[a];
  out[1 + Dim] = cF;
}

// The planar profile in double precision, and its inverse: the distance at which a half-space has D.
class Profile {
 public:
  Profile(std::vector<double> table, double h)
      : t_(std::move(table)), h_(h), step_(2 * h / double(t_.size() / kC - 1)) {}
  // D, dD/dd and F at d (linear between entries).
  void at(double d, double& D, double& dD, double& F) const {
    const double u = (d + h_) / step_;
    if (!(u > 0)) {
      D = F = 1;
      dD = 0;
      return;
    }
    const auto last = t_.size() / kC - 1;
    const auto k = std::min(static_cast<std::size_t>(u), last - 1);
    const double f = std::min(u - double(k), 1.0);
    const double* a = t_.data() + kC * k;
    const double* b = a + kC;
    D = a[0] + f * (b[0] - a[0]);
    dD = a[1] + f * (b[1] - a[1]);
    F = a[2] + f * (b[2] - a[2]);
  }
  // The d in [-h, h] with D(d) = D (D falls with d), by bisection.
  [[nodiscard]] double distance_of(double D) const {
    double lo = -h_, hi = h_;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      double v = 0, dv = 0, f = 0;
      at(mid, v, dv, f);
      (v > D ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }

 private:
  static constexpr std::size_t kC = VolumeMap<2, double>::kProfileColumns;
  std::vector<double> t_;
  double h_, step_;
};

// One node's fields: the equivalent distance, its gradient and F's difference from the half-space's. A
// node beyond every solid's reach is the plane itself (the distance, its gradient, no difference); else its
// D, grad D and F come from the quadrature's differences added to the tangent half-space's exact profile, and
// the equivalent distance from D.
template <int Dim, class Real>
void node_values(const Solids<Dim, Real>& sol, const std::vector<Voxel>& voxels, const Profile& prof,
                 double q, const P& x, double eps, double* out) {
  const double phi = sol.distance(x);
  P n{};
  double len = 0;
  for (int a = 0; a < Dim; ++a) {
    P up = x, dn = x;
    up[a] += eps;
    dn[a] -= eps;
    n[a] = (sol.distance(up) - sol.distance(dn)) / (2 * eps);
    len += n[a] * n[a];
  }
  len = std::sqrt(len);
  if (len > 0)
    for (int a = 0; a < Dim; ++a) n[a] /= len;
  out[0] = phi;
  for (int a = 0; a < Dim; ++a) out[1 + a] = n[a];
  out[1 + Dim] = 0;
  const double h = sol.reach();
  if (!(phi < h + 2 * q * std::sqrt(double(Dim))) || phi < -h) return;
  double c[2 + Dim];
  node_corrections(sol, voxels, q, x, phi, n, c);
  double D = 0, dD = 0, F = 0;
  prof.at(phi, D, dD, F);
  D += c[0];
  F += c[1 + Dim];
  P grad{};
  for (int a = 0; a < Dim; ++a) grad[a] = dD * n[a] + c[1 + a];
  if (!(D > 0)) {  // no solid within reach after all
    out[0] = std::max(phi, h);
    return;
  }
  const double pe = D >= 1 ? -h : prof.distance_of(D);
  double De = 0, dDe = 0, Fe = 0;
  prof.at(pe, De, dDe, Fe);
  out[0] = pe;
  if (std::abs(dDe) * h > 1e-6)
    for (int a = 0; a < Dim; ++a) out[1 + a] = grad[a] / dDe;
  out[1 + Dim] = F - Fe;
}

}  // namespace

template <int Dim, class Real>
std::vector<Real> volume_map_planar_profile(KernelKind kernel, Real support, Real spacing, int count) {
  constexpr std::size_t kC = VolumeMap<Dim, Real>::kProfileColumns;
  const double h = double(support), sp = double(spacing);
  std::vector<Real> out(kC * static_cast<std::size_t>(count));
  with_kernel<Dim, double>(kernel, h, [&](const auto w) {
    // Over the plane at height z: A(z) = int W, An(z) = int W'(r)/r z^2 and At(z) = int W'(r)/r t^2 (t one
    // direction in the plane); S(z): the ball's section.
    constexpr int kR = 400;
    struct Plane {
      double A = 0, An = 0, At = 0;
    };
    const auto plane = [&](double z) {
      Plane p;
      z = std::abs(z);
      if (z >= h) return p;
      if (Dim == 3) {  // polar about the foot of x: r from z to h, r dr = rho drho
        const double dr = (h - z) / kR;
        for (int k = 0; k < kR; ++k) {
          const double r = z + (k + 0.5) * dr;
          p.A += 2 * M_PI * w.W(r) * r * dr;
          p.At += M_PI * w.dW(r) * (r * r - z * z) * dr;  // int W'/r rho^2 cos^2 = pi int W' (r^2 - z^2) dr
        }
        p.An = -2 * M_PI * z * z * w.W(z);  // z^2 int W'(r)/r dA = z^2 2 pi int_z^h W'(r) dr
        return p;
      }
      const double t1 = std::sqrt(h * h - z * z), dt = t1 / kR;  // both sides of the line
      for (int k = 0; k < kR; ++k) {
        const double t = (k + 0.5) * dt, r = std::sqrt(z * z + t * t);
        const double f = r > 0 ? w.dW(r) / r : 0.0;
        p.A += 2 * w.W(r) * dt;
        p.An += 2 * f * z * z * dt;
        p.At += 2 * f * t * t * dt;
      }
      return p;
    };
    const auto section = [&](double z) {
      const double r2 = std::max(h * h - z * z, 0.0);
      return Dim == 3 ? M_PI * r2 : 2 * std::sqrt(r2);
    };
    const double ball = Dim == 3 ? 4.0 / 3.0 * M_PI * h * h * h : M_PI * h * h;
    const double step = 2 * h / (count - 1);
    // The lattice's layers beyond the wall: sums over k >= 0 of s times the plane's at d + (k + 1/2) s.
    const auto layers = [&](double d) {
      Plane sum;
      for (double z = d + sp / 2; z < h; z += sp) {
        const Plane p = plane(z);
        sum.A += sp * p.A;
        sum.An += sp * p.An;
        sum.At += sp * p.At;
      }
      return sum;
    };
    // The continuous integrals int_d^h dz, from the top down (F always; the others where spacing = 0).
    constexpr int kFine = 8;
    const double dz = step / kFine;
    Plane cont;
    double F = 0;
    for (int k = count - 1; k >= 0; --k) {
      const double d = -h + k * step;
      if (k < count - 1)
        for (int s = 0; s < kFine; ++s) {
          const double z = d + (s + 0.5) * dz;
          const Plane p = plane(z);
          cont.A += p.A * dz;
          cont.An += p.An * dz;
          cont.At += p.At * dz;
          F += section(z) * dz / ball;
        }
      const auto e = kC * static_cast<std::size_t>(k);
      const Plane v = sp > 0 ? layers(d) : cont;
      out[e] = static_cast<Real>(v.A);
      out[e + 1] = static_cast<Real>(sp > 0 ? (layers(d + step / 4).A - layers(d - step / 4).A) / (step / 2)
                                            : -plane(d).A);
      out[e + 2] = static_cast<Real>(F);
      out[e + 3] = static_cast<Real>(v.An);
      out[e + 4] = static_cast<Real>(v.At);
    }
  });
  return out;
}

namespace {

// The kernel integrated over a line (line(rho) = int W(sqrt(rho^2 + t^2)) dt over all t) as a table in
// rho over [0, h], linear between entries.
class LineIntegral {
 public:
  template <class Kernel>
  LineIntegral(const Kernel& w, double h) : h_(h), t_(kEntries + 1) {
    constexpr int kSteps = 400;
    for (int k = 0; k <= kEntries; ++k) {
      const double rho = h * k / kEntries, t1 = std::sqrt(std::max(h * h - rho * rho, 0.0)), dt = t1 / kSteps;
      double s = 0;
      for (int i = 0; i < kSteps; ++i) {
        const double t = (i + 0.5) * dt;
        s += w.W(std::sqrt(rho * rho + t * t)) * dt;
      }
      t_[static_cast<std::size_t>(k)] = 2 * s;
    }
  }
  [[nodiscard]] double operator()(double rho) const {
    const double u = rho / h_ * kEntries;
    if (!(u < kEntries)) return 0;
    const auto k = static_cast<std::size_t>(u);
    const double f = u - double(k);
    return t_[k] + f * (t_[k + 1] - t_[k]);
  }

 private:
  static constexpr int kEntries = 4096;
  double h_;
  std::vector<double> t_;
};

// The overlap of k faces of the layered lattice: the sum over rows z_i = d_i + (n_i + 1/2) s < h (n_i >= 0)
// of s^k times the kernel integrated over the other Dim - k axes at (z_1 .. z_k).
template <class Integrated>
double overlap_sum(int k, const double* d, double s, double h, const Integrated& f) {
  double sum = 0;
  const double h2 = h * h;
  for (double z0 = d[0] + s / 2; z0 < h; z0 += s)
    for (double z1 = d[1] + s / 2; z1 < h; z1 += s) {
      if (k == 2) {
        const double r2 = z0 * z0 + z1 * z1;
        if (r2 < h2) sum += f(std::sqrt(r2));
        continue;
      }
      for (double z2 = d[2] + s / 2; z2 < h; z2 += s) {
        const double r2 = z0 * z0 + z1 * z1 + z2 * z2;
        if (r2 < h2) sum += f(std::sqrt(r2));
      }
    }
  return sum * std::pow(s, k);
}

// A table of overlap_sum over [-h, h]^k, `count` entries per axis (first fastest): value and its
// derivative in the first distance (central differences).
template <class Real, class Integrated>
std::vector<Real> overlap_table(int k, int count, double s, double h, const Integrated& f) {
  std::size_t total = 1;
  for (int i = 0; i < k; ++i) total *= static_cast<std::size_t>(count);
  std::vector<Real> out(2 * total);
  const double step = 2 * h / (count - 1), eps = 1e-4 * h;
  parallel_chunks(total, 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t idx = b; idx < e; ++idx) {
      double d[3] = {0, 0, 0};
      std::size_t rest = idx;
      for (int i = 0; i < k; ++i) {
        d[i] = -h + step * double(rest % static_cast<std::size_t>(count));
        rest /= static_cast<std::size_t>(count);
      }
      out[2 * idx] = static_cast<Real>(overlap_sum(k, d, s, h, f));
      double up[3] = {d[0] + eps, d[1], d[2]}, dn[3] = {d[0] - eps, d[1], d[2]};
      out[2 * idx + 1] =
          static_cast<Real>((overlap_sum(k, up, s, h, f) - overlap_sum(k, dn, s, h, f)) / (2 * eps));
    }
  });
  return out;
}

// The grid of the solids other than the tank (boxes, shapes).
template <int Dim, class Real>
void build_grid(const SolidGuard<Dim, Real>& solids, KernelKind kernel, double h, double p, double spacing,
                int profile_count, VolumeMap<Dim, Real>& m) {
  P lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  const auto take = [&](int a, double l, double u) {
    lo[a] = std::min(lo[a], l);
    hi[a] = std::max(hi[a], u);
  };
  for (int a = 0; a < Dim; ++a) {
    for (const auto& b : solids.boxes) take(a, double(b.lo[a]), double(b.hi[a]));
    for (const auto& g : solids.grids)
      take(a, double(g.origin[a]), double(g.origin[a]) + double(g.pitch) * (g.n[a] - 1));
  }
  const double grow = h + p;
  double nodes = 1;
  for (int a = 0; a < Dim; ++a) {
    m.origin[a] = static_cast<Real>(lo[a] - grow);
    m.n[a] = static_cast<std::int32_t>(std::ceil((hi[a] - lo[a] + 2 * grow) / p)) + 1;
    nodes *= m.n[a];
  }
  if (nodes > 4e8)
    throw InputError("boundary.model: volume-map: the map's grid would hold " + std::to_string(nodes) +
                     " nodes (pitch " + std::to_string(p) + " m); coarsen the spacing or use particle walls");
  m.pitch = static_cast<Real>(p);
  constexpr int kF = VolumeMap<Dim, Real>::kFields;
  m.nodes.assign(static_cast<std::size_t>(nodes) * kF, Real(0));
  SolidGuard<Dim, Real> others = solids;
  others.container = false;
  const Solids<Dim, Real> sol(others, h);
  const double q = p / 4;
  std::vector<Voxel> voxels;
  with_kernel<Dim, double>(kernel, h, [&](const auto w) { voxels = quadrature_voxels<Dim>(w, h, q); });
  const double eps = 1e-4 * p;
  const Profile prof(volume_map_planar_profile<Dim, double>(kernel, h, spacing, profile_count), h);
  const auto nx = static_cast<std::size_t>(m.n[0]);
  const std::size_t rows = static_cast<std::size_t>(nodes) / nx;
  // Each row of nodes on its own: the values do not depend on the thread count.
  parallel_chunks(rows, 1, [&](std::size_t row, std::size_t) {
    const std::size_t j = row % static_cast<std::size_t>(m.n[1]), k = row / static_cast<std::size_t>(m.n[1]);
    for (std::size_t i = 0; i < nx; ++i) {
      P x{};
      const std::size_t idx[3] = {i, j, k};
      for (int a = 0; a < Dim; ++a) x[a] = double(m.origin[a]) + p * double(idx[a]);
      double out[2 + Dim];
      node_values(sol, voxels, prof, q, x, eps, out);
      Real* node = m.nodes.data() + (row * nx + i) * kF;
      for (int t = 0; t < kF; ++t) node[t] = static_cast<Real>(out[t]);
    }
  });
}

}  // namespace

template <int Dim, class Real>
VolumeMap<Dim, Real> build_volume_map(const SolidGuard<Dim, Real>& solids, KernelKind kernel, Real support,
                                      Real pitch, Real spacing) {
  VolumeMap<Dim, Real> m;
  m.built = true;
  m.reach = support;
  constexpr int kProfile = 2049;
  m.profile = volume_map_planar_profile<Dim, Real>(kernel, support, spacing, kProfile);
  m.profile_step = Real(2) * support / Real(kProfile - 1);
  const double h = double(support), s = double(spacing);
  if (solids.container) {
    m.tank = true;
    m.lo = solids.lo;
    m.hi = solids.hi;
    m.open_axis = solids.open_axis;
    constexpr int kEdge = 129, kCorner = 33;
    m.table_count[0] = kEdge;
    m.table_count[1] = Dim == 3 ? kCorner : 0;
    with_kernel<Dim, double>(kernel, h, [&](const auto w) {
      if constexpr (Dim == 3) {
        const LineIntegral line(w, h);
        m.edge = overlap_table<Real>(2, kEdge, s, h, line);
        m.corner = overlap_table<Real>(3, kCorner, s, h, [&](double r) { return w.W(r); });
      } else {
        m.edge = overlap_table<Real>(2, kEdge, s, h, [&](double r) { return w.W(r); });
      }
    });
  }
  if (!solids.boxes.empty() || !solids.grids.empty())
    build_grid(solids, kernel, h, double(pitch), s, kProfile, m);
  return m;
}

#define CELLSPH_VOLUME_MAP_INSTANTIATE(D, R)                                                     \
  template VolumeMap<D, R> build_volume_map<D, R>(const SolidGuard<D, R>&, KernelKind, R, R, R); \
  template std::vector<R> volume_map_planar_profile<D, R>(KernelKind, R, R, int);
CELLSPH_VOLUME_MAP_INSTANTIATE(2, float)
CELLSPH_VOLUME_MAP_INSTANTIATE(2, double)
CELLSPH_VOLUME_MAP_INSTANTIATE(3, float)
CELLSPH_VOLUME_MAP_INSTANTIATE(3, double)
#undef CELLSPH_VOLUME_MAP_INSTANTIATE

}  // namespace cellsph
