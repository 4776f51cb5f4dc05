#pragma once
// Walls without wall particles (WallModel::VolumeMap, scene key boundary.model = "volume-map"), after
// Bender, Kugelstadt, Weiler & Koschier 2019 ("Volume maps: an implicit boundary representation for SPH")
// and Koschier & Bender 2017 (density maps). Every solid of the SolidGuard (the tank, box obstacles, shaped
// obstacles and containers) is one map on a grid, built once at start (build_volume_map, bender2019.cpp).
// At a fluid particle x the map gives, for the solids together:
//   D(x) = int_solid W(x - y) dy,  grad D(x),  F(x) = |solid within the support ball| / |ball|,
// so the walls add rho0 D to the density and rho0 grad D to its gradient: the continuous limit of Akinci's
// sum of psi_b W_ib over wall particles, exact instead of sampled. The DFSPH and IISPH passes take the walls
// as one neighbour of i (models/dfsph.hpp), whose weighted gradient w_b grad W_ib is rho0 grad D; where a
// pass needs the wall's position (the no-slip viscosity, the hydrostatic wall pressure) the neighbour is
// the equivalent particle: the point x_b at distance r_b from x along -grad D and the volume V_b with
// V_b W(r_b) = D and V_b |W'(r_b)| = |grad D|, which exists for every kernel whose W / |W'| falls from
// infinity at 0 to 0 at h (cubic, Wendland, poly6). F counts the solid as the particles it replaces in the
// divergence solve's neighbour test. Bender et al. place their point half a particle radius below the
// surface and scale their volume by measured factors; the equivalent particle needs neither.
//
// The map stores, per node, the equivalent distance phi_e: the distance at which a half-space has the
// solids' D (a 1D table, the planar profile, inverted), with its gradient, and the difference of F from the
// half-space's. A particle's D is the profile at the interpolated phi_e, grad D the profile's slope times
// the interpolated gradient: along a flat wall phi_e is the distance itself, linear, so D is exact at any
// pitch; near edges, corners and curved solids phi_e is smooth where the distance to the nearest solid has
// a ridge, and the nodes' D comes from a quadrature over the solid (voxels of a quarter pitch filled by the
// distance at their centres, minus the same quadrature over the tangent half-space added to the exact
// profile, so that the quadrature's own error cancels).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cellsph/core/hd.hpp"
#include "cellsph/physics/kernels.hpp"
#include "cellsph/solver/config.hpp"
#include "cellsph/solver/particle_view.hpp"

namespace cellsph {

// The map as a pass reads it (pointers into VolumeMap's arrays).
template <int Dim, class Real>
struct VolumeMapView {
  Real reach = 0;
  const Real* profile = nullptr;
  Real inv_profile_step = 0;
  std::int32_t profile_count = 0;
  bool tank = false;
  Vec<Dim, Real> lo{}, hi{};
  int open_axis = -1;
  std::int32_t table_count[2] = {0, 0};
  const Real* edge = nullptr;
  const Real* corner = nullptr;
  Vec<Dim, Real> origin{};
  Real inv_pitch = 0;
  std::int32_t n[3] = {1, 1, 1};
  const Real* nodes = nullptr;  // null: no solid but the tank
};

template <int Dim, class Real>
VolumeMapView<Dim, Real> volume_map_view(const VolumeMap<Dim, Real>& m) {
  VolumeMapView<Dim, Real> v;
  v.reach = m.reach;
  v.profile = m.profile.data();
  v.inv_profile_step = Real(1) / m.profile_step;
  v.profile_count = static_cast<std::int32_t>(m.profile.size() / VolumeMap<Dim, Real>::kProfileColumns);
  v.tank = m.tank;
  v.lo = m.lo;
  v.hi = m.hi;
  v.open_axis = m.open_axis;
  v.table_count[0] = m.table_count[0];
  v.table_count[1] = m.table_count[1];
  v.edge = m.edge.data();
  v.corner = m.corner.data();
  v.origin = m.origin;
  v.inv_pitch = m.pitch > 0 ? Real(1) / m.pitch : Real(0);
  for (int a = 0; a < 3; ++a) v.n[a] = m.n[a];
  v.nodes = m.nodes.empty() ? nullptr : m.nodes.data();
  return v;
}

// What the solids give at one point.
template <int Dim, class Real>
struct VolumeMapSample {
  Real D = 0;              // int_solid W(x - y) dy (the layered lattice's sum)
  Vec<Dim, Real> grad{};   // grad D
  Real F = 0;              // the solid's share of the support ball
  Vec<Dim, Real> hydro{};  // T g, T = int_solid (x - y) (x) grad W(x - y) dy: the walls' hydrostatic term
  bool near = false;       // a solid is within the support
};

// The half-space profile at one distance: D, dD/dd, F, and T's parts along the normal (alpha) and along
// each direction of the plane (beta).
template <class Real>
struct VolumeMapProfile {
  Real D = 0, dD = 0, F = 0, alpha = 0, beta = 0;
};

// The half-space profile at signed distance d (the table, linear between entries).
template <int Dim, class Real>
CELLSPH_HD inline VolumeMapProfile<Real> volume_map_profile(const VolumeMapView<Dim, Real>& m, Real d) {
  constexpr int kC = VolumeMap<Dim, Real>::kProfileColumns;
  const Real t = (d + m.reach) * m.inv_profile_step;
  const auto last = m.profile_count - 1;
  const auto k = std::min(static_cast<std::int32_t>(std::max(t, Real(0))), last - 1);
  const Real u = std::min(std::max(t - Real(k), Real(0)), Real(1));
  const Real* a = m.profile + kC * k;
  const Real* b = a + kC;
  VolumeMapProfile<Real> p;
  p.D = a[0] + u * (b[0] - a[0]);
  p.dD = a[1] + u * (b[1] - a[1]);
  p.F = a[2] + u * (b[2] - a[2]);
  p.alpha = a[3] + u * (b[3] - a[3]);
  p.beta = a[4] + u * (b[4] - a[4]);
  return p;
}

// A half-space's T g at distance d with unit normal n (into the fluid).
template <int Dim, class Real>
CELLSPH_HD inline Vec<Dim, Real> volume_map_hydro(const VolumeMapProfile<Real>& p, const Vec<Dim, Real>& n,
                                                  const Vec<Dim, Real>& g) {
  const Real gn = dot(n, g);
  return n * (p.alpha * gn) + (g - n * gn) * p.beta;
}

// The 2^K corners of a multilinear interpolation in a grid of count[a] entries per axis (first fastest)
// about the cell at `base` with fractions `frac`: f(index, weight) for each.
template <int K, class Real, class F>
CELLSPH_HD inline void volume_map_corners(const std::int32_t* base, const Real* frac,
                                          const std::int32_t* count, const F& f) {
  for (int c = 0; c < (1 << K); ++c) {
    Real w = 1;
    std::int64_t idx = 0, stride = 1;
    for (int a = 0; a < K; ++a) {
      const int bit = (c >> a) & 1;
      w *= bit ? frac[a] : Real(1) - frac[a];
      idx += stride * (base[a] + bit);
      stride *= count[a];
    }
    f(idx, w);
  }
}

// A table over [-reach, reach]^K (K = 2: two faces' overlap, 3: three), `count` entries per axis, first
// index fastest, two values per entry (the overlap and its derivative in the first distance): both at d,
// multilinearly.
template <int K, class Real>
CELLSPH_HD inline void volume_map_table(const Real* table, std::int32_t count, Real reach, const Real* d,
                                        Real& value, Real& slope) {
  const Real scale = Real(count - 1) / (2 * reach);
  std::int32_t base[K];
  Real frac[K];
  for (int a = 0; a < K; ++a) {
    const Real t = std::min(std::max((d[a] + reach) * scale, Real(0)), Real(count - 1));
    base[a] = std::min(static_cast<std::int32_t>(t), count - 2);
    frac[a] = t - Real(base[a]);
  }
  value = slope = 0;
  std::int32_t counts[K];
  for (int a = 0; a < K; ++a) counts[a] = count;
  volume_map_corners<K>(base, frac, counts, [&](std::int64_t idx, Real w) {
    value += w * table[2 * idx];
    slope += w * table[2 * idx + 1];
  });
}

// The overlap of k faces (k = 1: the profile) at distances d[0..k) and its derivative in each.
template <int Dim, class Real>
CELLSPH_HD inline Real volume_map_overlap(const VolumeMapView<Dim, Real>& m, int k, const Real* d,
                                          Real* slope) {
  Real value = 0;
  if (k == 1) {
    const auto p = volume_map_profile(m, d[0]);
    slope[0] = p.dD;
    return p.D;
  }
  const Real* table = k == 2 ? m.edge : m.corner;
  const std::int32_t count = m.table_count[k - 2];
  Real perm[3];
  for (int i = 0; i < k; ++i) {  // the table's slope is in its first distance: d_i first (symmetric)
    for (int j = 0; j < k; ++j) perm[j] = d[j];
    perm[0] = d[i];
    perm[i] = d[0];
    Real v = 0;
    if (k == 2)
      volume_map_table<2>(table, count, m.reach, perm, v, slope[i]);
    else
      volume_map_table<3>(table, count, m.reach, perm, v, slope[i]);
    if (i == 0) value = v;
  }
  return value;
}

// The tank's walls: the complement of the fluid's box (open upwards on open_axis), by inclusion and
// exclusion of its faces within reach: D = sum over sets of faces, one per axis at most, of
// (-1)^(|set| + 1) times their overlap.
template <int Dim, class Real>
CELLSPH_HD inline void volume_map_tank(const VolumeMapView<Dim, Real>& m, const Vec<Dim, Real>& x,
                                       const Vec<Dim, Real>& g, VolumeMapSample<Dim, Real>& s) {
  Real d[Dim][2], sg[Dim][2];
  int cnt[Dim];
  int combos = 1;
  for (int a = 0; a < Dim; ++a) {
    cnt[a] = 0;
    const Real dl = x[a] - m.lo[a], du = m.hi[a] - x[a];
    if (dl < m.reach) {
      d[a][cnt[a]] = dl;
      sg[a][cnt[a]++] = 1;
    }
    if (a != m.open_axis && du < m.reach) {
      d[a][cnt[a]] = du;
      sg[a][cnt[a]++] = -1;
    }
    combos *= cnt[a] + 1;
  }
  for (int c = 1; c < combos; ++c) {
    Real args[3], slope[3], sign[3];
    int axis[3], k = 0, rest = c;
    for (int a = 0; a < Dim; ++a) {
      const int pick = rest % (cnt[a] + 1);
      rest /= cnt[a] + 1;
      if (pick == 0) continue;
      args[k] = d[a][pick - 1];
      sign[k] = sg[a][pick - 1];
      axis[k++] = a;
    }
    const Real parity = (k % 2 == 1) ? Real(1) : Real(-1);
    s.D += parity * volume_map_overlap(m, k, args, slope);
    for (int i = 0; i < k; ++i) s.grad[axis[i]] += parity * sign[i] * slope[i];
    if (k == 1) {  // F and T: the faces' sums (their overlaps at edges counted twice)
      const auto p = volume_map_profile(m, args[0]);
      s.F += p.F;
      Vec<Dim, Real> n{};
      n[axis[0]] = sign[0];
      s.hydro += volume_map_hydro(p, n, g);
    }
  }
}

// The grid's solids (boxes, shapes) at x: the node fields interpolated multilinearly, then the profile at
// the equivalent distance. Off the grid (beyond every such solid's reach) nothing.
template <int Dim, class Real>
CELLSPH_HD inline void volume_map_grid(const VolumeMapView<Dim, Real>& m, const Vec<Dim, Real>& x,
                                       const Vec<Dim, Real>& g, VolumeMapSample<Dim, Real>& s) {
  constexpr int kF = VolumeMap<Dim, Real>::kFields;
  std::int32_t base[3] = {0, 0, 0};
  Real frac[3] = {0, 0, 0};
  for (int a = 0; a < Dim; ++a) {
    const Real u = (x[a] - m.origin[a]) * m.inv_pitch;
    if (!(u >= 0 && u <= Real(m.n[a] - 1))) return;
    const auto k = std::min(static_cast<std::int32_t>(u), m.n[a] - 2);
    base[a] = k;
    frac[a] = u - Real(k);
  }
  Real f[kF] = {};
  volume_map_corners<Dim>(base, frac, m.n, [&](std::int64_t idx, Real w) {
    const Real* node = m.nodes + idx * kF;
    for (int k = 0; k < kF; ++k) f[k] += w * node[k];
  });
  if (!(f[0] < m.reach)) return;
  const auto p = volume_map_profile(m, f[0]);
  s.D += p.D;
  Vec<Dim, Real> n{};
  for (int a = 0; a < Dim; ++a) {
    s.grad[a] += p.dD * f[1 + a];
    n[a] = f[1 + a];
  }
  s.F += p.F + f[1 + Dim];
  const Real len = norm(n);
  if (len > 0) s.hydro += volume_map_hydro(p, Vec<Dim, Real>(n / len), g);
}

// The solids' D, grad D, F and T g (g: gravity) at x: the tank's and the grid's, summed.
template <int Dim, class Real>
CELLSPH_HD inline VolumeMapSample<Dim, Real> volume_map_sample(const VolumeMapView<Dim, Real>& m,
                                                               const Vec<Dim, Real>& x,
                                                               const Vec<Dim, Real>& g = {}) {
  VolumeMapSample<Dim, Real> s;
  if (m.tank) volume_map_tank(m, x, g, s);
  if (m.nodes) volume_map_grid(m, x, g, s);
  s.D = std::max(s.D, Real(0));
  s.F = std::min(std::max(s.F, Real(0)), Real(1));
  s.near = s.D > 0;
  return s;
}

// The equivalent particle of a sample: r_b with W(r_b) / |W'(r_b)| = D / |grad D| (bisection: that ratio
// falls with r), V_b = D / W(r_b), x_i - x_b = -r_b grad D / |grad D|. |grad D| = 0 (a particle between
// two walls of one solid, their pulls cancelling): r_b = 0, x_b = x_i.
template <int Dim, class Real>
struct VolumeMapParticle {
  Real volume = 0;
  Vec<Dim, Real> xib{};
};
template <int Dim, class Real, class Kernel>
CELLSPH_HD inline VolumeMapParticle<Dim, Real> volume_map_particle(const VolumeMapSample<Dim, Real>& s,
                                                                   const Kernel& w, Real reach) {
  VolumeMapParticle<Dim, Real> p;
  const Real g = norm(s.grad);
  Real lo = 0, hi = reach;
  if (g > 0) {
    for (int it = 0; it < 40; ++it) {
      const Real mid = Real(0.5) * (lo + hi);
      // W(mid) / -W'(mid) > D / g: still short of r_b.
      if (w.W(mid) * g > -w.dW(mid) * s.D)
        lo = mid;
      else
        hi = mid;
    }
  } else {
    hi = 0;
  }
  const Real r = Real(0.5) * (lo + hi);
  const Real wr = w.W(r);
  p.volume = wr > 0 ? s.D / wr : Real(0);
  if (g > 0) p.xib = s.grad * (-r / g);
  return p;
}

// Once a step (the implicit models, before their density pass), for each fluid particle i: the walls'
// part of its density rho0_i D (vm_rho), of its gradient rho0_i grad D (vm_g), the equivalent particle's
// weight rho0_i V_b (vm_w) and x_i - x_b (vm_x), the particles the solid replaces in i's support, F
// times a full support's count (vm_count), and rho0_i T g (vm_h: the hydrostatic wall pressure's term,
// m_i / rho_i times it). Zero where no solid is within the support.
template <int Dim, class Real, class Kernel>
struct VolumeMapLookupPass {
  ParticleView<Dim, Real> pv;
  VolumeMapView<Dim, Real> map;
  Kernel w;
  Real full;  // particles a full support holds (its volume over the particle's)
  Vec<Dim, Real> gravity;

  CELLSPH_HD void operator()(std::size_t i) const {
    const auto s = volume_map_sample(map, pv.x[i], gravity);
    const Real rho0 = pv.rho0[i];
    if (!s.near) {
      pv.vm_rho[i] = 0;
      pv.vm_g[i] = Vec<Dim, Real>{};
      pv.vm_w[i] = 0;
      pv.vm_x[i] = Vec<Dim, Real>{};
      pv.vm_count[i] = 0;
      pv.vm_h[i] = Vec<Dim, Real>{};
      return;
    }
    const auto b = volume_map_particle(s, w, map.reach);
    pv.vm_rho[i] = rho0 * s.D;
    pv.vm_g[i] = s.grad * rho0;
    pv.vm_w[i] = rho0 * b.volume;
    pv.vm_x[i] = b.xib;
    pv.vm_count[i] = s.F * full;
    pv.vm_h[i] = s.hydro * rho0;
  }
};

// The map of the config's solids (cfg.guard) for its density kernel and support, with nodes `pitch`
// apart, for a fluid of particle spacing `spacing` (bender2019.cpp). Throws InputError when the grid would
// be too large.
template <int Dim, class Real>
VolumeMap<Dim, Real> build_volume_map(const SolidGuard<Dim, Real>& solids, KernelKind kernel, Real support,
                                      Real pitch, Real spacing);

// The half-space profile of a kernel (the map's table; bender2019.cpp): D, dD/dd and F at d = -h + 2 h k /
// (count - 1), k < count. With spacing s > 0, D is that of the fluid's lattice continued into the solid in
// layers: D(d) = sum over k >= 0 of s A(d + (k + 1/2) s), A(z) the kernel's integral over a plane at height
// z (a particle at d = s/2 then has the density of one inside the fluid); with s = 0 the integral
// int_d^h A(z) dz. F is the ball's share beyond the plane.
template <int Dim, class Real>
std::vector<Real> volume_map_planar_profile(KernelKind kernel, Real support, Real spacing, int count);

}  // namespace cellsph
