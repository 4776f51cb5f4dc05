#include "cellsph/geometry/shape.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"

namespace cellsph::geometry {

namespace {

P3 sub(const P3& a, const P3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const P3& a, const P3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
P3 axpy(const P3& a, double s, const P3& d) {
  return {a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]};
}

double segment_distance2(const P3& p, const P3& a, const P3& b) {
  const P3 ab = sub(b, a);
  const double l2 = dot(ab, ab);
  double t = l2 > 0 ? dot(sub(p, a), ab) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  const P3 d = sub(p, axpy(a, t, ab));
  return dot(d, d);
}

// Squared distance from p to the triangle abc: the closest point by the Voronoi regions of the
// triangle's vertices, edges and face (Ericson, Real-Time Collision Detection, 5.1.5).
double triangle_distance2(const P3& p, const P3& a, const P3& b, const P3& c) {
  const P3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  P3 q;
  if (d1 <= 0 && d2 <= 0) {
    q = a;
  } else {
    const P3 bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    const P3 cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d3 >= 0 && d4 <= d3) {
      q = b;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
      q = axpy(a, d1 / (d1 - d3), ab);
    } else if (d6 >= 0 && d5 <= d6) {
      q = c;
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
      q = axpy(a, d2 / (d2 - d6), ac);
    } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
      q = axpy(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b));
    } else if (va + vb + vc > 0) {
      const double v = vb / (va + vb + vc), w = vc / (va + vb + vc);
      q = axpy(axpy(a, v, ab), w, ac);
    } else {  // a degenerate (collinear) triangle: its edges
      return std::min({segment_distance2(p, a, b), segment_distance2(p, b, c), segment_distance2(p, c, a)});
    }
  }
  const P3 d = sub(p, q);
  return dot(d, d);
}

// A uniform grid of cells of one size over a box, each cell with the triangles that may reach into it
// (CSR: offsets, items).
struct Bins {
  P3 origin{};
  double cell = 1;
  std::array<long, 3> n{1, 1, 1};
  std::vector<std::uint64_t> offsets;
  std::vector<std::uint32_t> items;

  [[nodiscard]] long index(double x, int a) const {
    const double f = std::floor((x - origin[static_cast<std::size_t>(a)]) / cell);
    return static_cast<long>(std::clamp(f, -1.0, double(n[static_cast<std::size_t>(a)])));
  }
  [[nodiscard]] std::size_t flat(long i, long j, long k) const {
    return static_cast<std::size_t>((k * n[1] + j) * n[0] + i);
  }
};

}  // namespace

class MeshDistance {
 public:
  MeshDistance(TriangleMesh m, double spacing) : m_(std::move(m)) {
    P3 lo, hi;
    bounds(m_, lo, hi);
    double ext = 0;
    for (std::size_t a = 0; a < 3; ++a) ext = std::max(ext, hi[a] - lo[a]);
    // Parity bins in the (y, z) plane, about a spacing wide (at most 1024 across).
    {
      Bins& b = yz_;
      b.cell = std::max(spacing, ext / 1024);
      b.origin = {0, lo[1], lo[2]};
      b.n = {1, long(std::floor((hi[1] - lo[1]) / b.cell)) + 1,
             long(std::floor((hi[2] - lo[2]) / b.cell)) + 1};
      fill(b, [&](std::uint32_t t, auto&& add) {
        const auto [tlo, thi] = tri_bounds(t);
        for (long k = b.index(tlo[2], 2); k <= b.index(thi[2], 2); ++k)
          for (long j = b.index(tlo[1], 1); j <= b.index(thi[1], 1); ++j)
            if (j >= 0 && j < b.n[1] && k >= 0 && k < b.n[2]) add(b.flat(0, j, k));
      });
    }
    // Distance bins: cells of two spacings (at most 128 across), a triangle in every cell its bounds
    // overlap that its plane passes through.
    {
      Bins& b = xyz_;
      b.cell = std::max(2 * spacing, ext / 128);
      b.origin = lo;
      for (std::size_t a = 0; a < 3; ++a) b.n[a] = long(std::floor((hi[a] - lo[a]) / b.cell)) + 1;
      const double half_diag = 0.5 * std::sqrt(3.0) * b.cell * 1.001;
      fill(b, [&](std::uint32_t t, auto&& add) {
        const auto [tlo, thi] = tri_bounds(t);
        const auto& tr = m_.triangles[t];
        const P3 &A = m_.vertices[tr[0]], &B = m_.vertices[tr[1]], &C = m_.vertices[tr[2]];
        const P3 u = sub(B, A), v = sub(C, A);
        P3 nrm{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double len = std::sqrt(dot(nrm, nrm));
        for (long k = b.index(tlo[2], 2); k <= b.index(thi[2], 2); ++k)
          for (long j = b.index(tlo[1], 1); j <= b.index(thi[1], 1); ++j)
            for (long i = b.index(tlo[0], 0); i <= b.index(thi[0], 0); ++i) {
              if (i < 0 || j < 0 || k < 0 || i >= b.n[0] || j >= b.n[1] || k >= b.n[2]) continue;
              if (len > 0) {
                const P3 centre{b.origin[0] + (double(i) + 0.5) * b.cell,
                                b.origin[1] + (double(j) + 0.5) * b.cell,
                                b.origin[2] + (double(k) + 0.5) * b.cell};
                if (std::abs(dot(sub(centre, A), nrm)) / len > half_diag) continue;
              }
              add(b.flat(i, j, k));
            }
      });
    }
    volume_ = geometry::volume(m_);
    on_surface_ = 1e-12 * std::max(ext, 1e-300);
  }

  // Points closer than this to the surface are on it (rounding in the distance is far below it).
  [[nodiscard]] double on_surface() const { return on_surface_; }

  // The x of every crossing of the line (y, z) along x with the surface, sorted. A line through a
  // shared edge or vertex crosses once: the edge functions are evaluated the same way for both triangles
  // of an edge (vertices in index order), and a point on an edge belongs to the triangle on the side the
  // tie rule picks.
  void crossings(double y, double z, std::vector<double>& xs) const {
    xs.clear();
    const long j = yz_.index(y, 1), k = yz_.index(z, 2);
    if (j < 0 || k < 0 || j >= yz_.n[1] || k >= yz_.n[2]) return;
    const std::size_t c = yz_.flat(0, j, k);
    for (std::uint64_t e = yz_.offsets[c]; e < yz_.offsets[c + 1]; ++e) {
      const auto& t = m_.triangles[yz_.items[e]];
      const P3 &a = m_.vertices[t[0]], &b = m_.vertices[t[1]], &cc = m_.vertices[t[2]];
      const double area = (b[1] - a[1]) * (cc[2] - a[2]) - (b[2] - a[2]) * (cc[1] - a[1]);
      if (area == 0) continue;  // seen edge-on: its neighbours hold the crossing
      const double s = area > 0 ? 1 : -1;
      const double f0 = s * edge(t[1], t[2], y, z), f1 = s * edge(t[2], t[0], y, z),
                   f2 = s * edge(t[0], t[1], y, z);
      if (!covers(f0, t[1], t[2], s) || !covers(f1, t[2], t[0], s) || !covers(f2, t[0], t[1], s)) continue;
      const double sum = f0 + f1 + f2;
      if (!(sum > 0)) continue;
      // From a's x, so that a face at one x gives exactly that x (sites on it are on the surface).
      xs.push_back(a[0] + (f1 * (b[0] - a[0]) + f2 * (cc[0] - a[0])) / sum);
    }
    std::sort(xs.begin(), xs.end());
  }

  // The distance from p to the surface when it is at most `band`, else infinity.
  [[nodiscard]] double distance(const P3& p, double band) const {
    double best = band * band;
    bool found = false;
    long lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      const auto s = static_cast<std::size_t>(a);
      lo[a] = std::max(0L, xyz_.index(p[s] - band, a));
      hi[a] = std::min(xyz_.n[s] - 1, xyz_.index(p[s] + band, a));
      if (lo[a] > hi[a]) return std::numeric_limits<double>::infinity();
    }
    for (long k = lo[2]; k <= hi[2]; ++k)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long i = lo[0]; i <= hi[0]; ++i) {
          const std::size_t c = xyz_.flat(i, j, k);
          for (std::uint64_t e = xyz_.offsets[c]; e < xyz_.offsets[c + 1]; ++e) {
            const auto& t = m_.triangles[xyz_.items[e]];
            const double d2 = triangle_distance2(p, m_.vertices[t[0]], m_.vertices[t[1]], m_.vertices[t[2]]);
            if (d2 <= best) {
              best = d2;
              found = true;
            }
          }
        }
    return found ? std::sqrt(best) : std::numeric_limits<double>::infinity();
  }

  [[nodiscard]] double volume() const { return volume_; }
  [[nodiscard]] const TriangleMesh& mesh() const { return m_; }

 private:
  // The edge function of the edge i -> j at (y, z) in the (y, z) plane, computed from the vertex of
  // the lower index so that both triangles of an edge get bit-identical values (negated).
  [[nodiscard]] double edge(std::uint32_t i, std::uint32_t j, double y, double z) const {
    const bool fwd = i < j;
    const P3& p = m_.vertices[fwd ? i : j];
    const P3& q = m_.vertices[fwd ? j : i];
    const double e = (q[1] - p[1]) * (z - p[2]) - (q[2] - p[2]) * (y - p[1]);
    return fwd ? e : -e;
  }
  // Whether the point with the (orientation-normalised) edge function f is on the triangle's side of
  // the edge i -> j; on the edge itself (f = 0) only for edges whose normalised direction points down in
  // z (or along +y when level), so of two triangles on either side of an edge exactly one takes it.
  [[nodiscard]] bool covers(double f, std::uint32_t i, std::uint32_t j, double s) const {
    if (f > 0) return true;
    if (f < 0) return false;
    const double dy = s * (m_.vertices[j][1] - m_.vertices[i][1]),
                 dz = s * (m_.vertices[j][2] - m_.vertices[i][2]);
    return dz < 0 || (dz == 0 && dy > 0);
  }
  [[nodiscard]] std::pair<P3, P3> tri_bounds(std::uint32_t t) const {
    P3 lo = m_.vertices[m_.triangles[t][0]], hi = lo;
    for (std::size_t v = 1; v < 3; ++v)
      for (std::size_t a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], m_.vertices[m_.triangles[t][v]][a]);
        hi[a] = std::max(hi[a], m_.vertices[m_.triangles[t][v]][a]);
      }
    return {lo, hi};
  }
  // Counts, then fills, the cells' triangle lists (CSR).
  template <class Visit>
  void fill(Bins& b, Visit&& visit) const {
    const std::size_t cells = static_cast<std::size_t>(b.n[0] * b.n[1] * b.n[2]);
    b.offsets.assign(cells + 1, 0);
    for (std::uint32_t t = 0; t < m_.triangles.size(); ++t)
      visit(t, [&](std::size_t c) { ++b.offsets[c + 1]; });
    for (std::size_t c = 0; c < cells; ++c) b.offsets[c + 1] += b.offsets[c];
    b.items.resize(b.offsets[cells]);
    std::vector<std::uint64_t> next(b.offsets.begin(), b.offsets.end() - 1);
    for (std::uint32_t t = 0; t < m_.triangles.size(); ++t)
      visit(t, [&](std::size_t c) { b.items[next[c]++] = t; });
  }

  TriangleMesh m_;
  Bins yz_, xyz_;
  double volume_ = 0, on_surface_ = 0;
};

Shape Shape::sphere(const Sphere& s, int dim) {
  Shape out;
  out.kind_ = Kind::Sphere;
  out.dim_ = dim;
  out.sphere_ = s;
  for (std::size_t a = 0; a < 3; ++a) {
    out.lo_[a] = a < std::size_t(dim) ? s.center[a] - s.radius : 0;
    out.hi_[a] = a < std::size_t(dim) ? s.center[a] + s.radius : 0;
  }
  return out;
}

Shape Shape::cylinder(const Cylinder& c, int dim) {
  Shape out;
  out.kind_ = Kind::Cylinder;
  out.dim_ = dim;
  out.cylinder_ = c;
  const P3 top = axpy(c.base, c.height, c.axis);
  for (std::size_t a = 0; a < 3; ++a) {
    const double r = c.radius * std::sqrt(std::max(0.0, 1 - c.axis[a] * c.axis[a]));
    out.lo_[a] = a < std::size_t(dim) ? std::min(c.base[a], top[a]) - r : 0;
    out.hi_[a] = a < std::size_t(dim) ? std::max(c.base[a], top[a]) + r : 0;
  }
  return out;
}

Shape Shape::mesh(TriangleMesh m, double spacing) {
  Shape out;
  out.kind_ = Kind::Mesh;
  out.dim_ = 3;
  bounds(m, out.lo_, out.hi_);
  out.mesh_ = std::make_shared<const MeshDistance>(std::move(m), spacing);
  return out;
}

double Shape::volume() const {
  switch (kind_) {
    case Kind::Sphere:
      return dim_ == 2 ? M_PI * sphere_.radius * sphere_.radius
                       : 4.0 / 3.0 * M_PI * sphere_.radius * sphere_.radius * sphere_.radius;
    case Kind::Cylinder:
      return dim_ == 2 ? 2 * cylinder_.radius * cylinder_.height
                       : M_PI * cylinder_.radius * cylinder_.radius * cylinder_.height;
    case Kind::Mesh:
      return mesh_->volume();
  }
  return 0;
}

double Shape::area() const {
  switch (kind_) {
    case Kind::Sphere:
      return dim_ == 2 ? 2 * M_PI * sphere_.radius : 4 * M_PI * sphere_.radius * sphere_.radius;
    case Kind::Cylinder:
      return dim_ == 2 ? 2 * (2 * cylinder_.radius + cylinder_.height)
                       : 2 * M_PI * cylinder_.radius * (cylinder_.radius + cylinder_.height);
    case Kind::Mesh: {
      double a = 0;
      const auto& m = mesh_->mesh();
      for (const auto& t : m.triangles) {
        const P3 u = sub(m.vertices[t[1]], m.vertices[t[0]]), v = sub(m.vertices[t[2]], m.vertices[t[0]]);
        const P3 c{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        a += 0.5 * std::sqrt(dot(c, c));
      }
      return a;
    }
  }
  return 0;
}

Side Shape::classify(const P3& p, double band) const {
  auto from_sdf = [](double d) { return Side{d < 0 ? -1 : d > 0 ? 1 : 0, std::abs(d)}; };
  switch (kind_) {
    case Kind::Sphere: {
      P3 d = sub(p, sphere_.center);
      if (dim_ == 2) d[2] = 0;
      return from_sdf(std::sqrt(dot(d, d)) - sphere_.radius);
    }
    case Kind::Cylinder: {
      P3 q = sub(p, cylinder_.base);
      if (dim_ == 2) q[2] = 0;
      const double h = dot(q, cylinder_.axis);
      const P3 r = axpy(q, -h, cylinder_.axis);
      const double dx = std::sqrt(dot(r, r)) - cylinder_.radius;
      const double dy = std::abs(h - cylinder_.height / 2) - cylinder_.height / 2;
      const double ox = std::max(dx, 0.0), oy = std::max(dy, 0.0);
      return from_sdf(std::min(std::max(dx, dy), 0.0) + std::sqrt(ox * ox + oy * oy));
    }
    case Kind::Mesh: {
      thread_local std::vector<double> xs;
      mesh_->crossings(p[1], p[2], xs);
      const auto above = std::upper_bound(xs.begin(), xs.end(), p[0]);
      if (above != xs.begin() && *(above - 1) == p[0]) return {0, 0};
      Side s{(xs.end() - above) % 2 ? -1 : 1, mesh_->distance(p, std::max(band, mesh_->on_surface()))};
      if (s.distance <= mesh_->on_surface()) return {0, 0};
      if (s.distance > band) s.distance = std::numeric_limits<double>::infinity();
      return s;
    }
  }
  return {};
}

double lattice_sites(const Shape& s, double spacing, double margin) {
  double n = 1;
  for (int a = 0; a < s.dim(); ++a) {
    const auto k = static_cast<std::size_t>(a);
    n *= std::floor((s.hi()[k] - s.lo()[k] + 2 * margin) / spacing) + 3;
  }
  return n;
}

double lattice_reach(const Shape& s, double margin, int axis) {
  const auto k = static_cast<std::size_t>(axis);
  return std::max(std::abs(s.lo()[k] - margin), std::abs(s.hi()[k] + margin));
}

std::vector<P3> sample(const Shape& s, double spacing, bool outside, double depth) {
  const double margin = outside ? depth : 0;
  std::array<long, 3> lo{0, 0, 0}, n{1, 1, 1};
  for (int a = 0; a < s.dim(); ++a) {
    const auto k = static_cast<std::size_t>(a);
    if (!(lattice_reach(s, margin, a) / spacing < kMaxLatticeIndex))
      throw std::invalid_argument("geometry::sample: the shape lies more than 2^50 spacings from the origin");
    lo[k] = static_cast<long>(std::floor((s.lo()[k] - margin) / spacing - 0.5));
    n[k] = static_cast<long>(std::ceil((s.hi()[k] + margin) / spacing - 0.5)) - lo[k] + 1;
  }
  const std::size_t rows = static_cast<std::size_t>(n[1] * n[2]);
  std::vector<std::vector<P3>> per_row(rows);
  const double band = std::isfinite(depth) ? depth : 0;
  const int want = outside ? 1 : -1;
  parallel_chunks(rows, 16, [&](std::size_t r0, std::size_t r1) {
    std::vector<double> xs;
    for (std::size_t r = r0; r < r1; ++r) {
      const long j = static_cast<long>(r) % n[1] + lo[1], k = static_cast<long>(r) / n[1] + lo[2];
      const double y = (double(j) + 0.5) * spacing, z = s.dim() == 3 ? (double(k) + 0.5) * spacing : 0;
      auto& out = per_row[r];
      if (s.kind_ == Shape::Kind::Mesh) s.mesh_->crossings(y, z, xs);
      for (long i = lo[0]; i < lo[0] + n[0]; ++i) {
        const P3 p{(double(i) + 0.5) * spacing, y, z};
        Side side;
        if (s.kind_ == Shape::Kind::Mesh) {
          // The row's crossings give the side; the distance only when a band is asked for.
          const auto above = std::upper_bound(xs.begin(), xs.end(), p[0]);
          if (above != xs.begin() && *(above - 1) == p[0]) continue;  // on the surface
          side.sign = (xs.end() - above) % 2 ? -1 : 1;
          if (side.sign != want) continue;
          // A site on the surface (a face through the row's sites) is on neither side.
          const double eps = s.mesh_->on_surface();
          side.distance = s.mesh_->distance(p, std::max(band, eps));
          if (side.distance <= eps) continue;
        } else {
          side = s.classify(p, band);
        }
        if (side.sign == want && (band == 0 || side.distance <= depth)) out.push_back(p);
      }
    }
  });
  std::vector<P3> all;
  std::size_t total = 0;
  for (const auto& r : per_row) total += r.size();
  all.reserve(total);
  for (const auto& r : per_row) all.insert(all.end(), r.begin(), r.end());
  return all;
}

std::vector<double> signed_distance_grid(const Shape& s, const P3& origin, double pitch,
                                         const std::array<long, 3>& n, double band) {
  const std::size_t rows = static_cast<std::size_t>(n[1] * n[2]), row = static_cast<std::size_t>(n[0]);
  std::vector<double> out(rows * row, band);
  parallel_chunks(rows, 16, [&](std::size_t r0, std::size_t r1) {
    std::vector<double> xs;
    for (std::size_t r = r0; r < r1; ++r) {
      const long j = static_cast<long>(r) % n[1], k = static_cast<long>(r) / n[1];
      const double y = origin[1] + double(j) * pitch, z = s.dim() == 3 ? origin[2] + double(k) * pitch : 0.0;
      // A mesh's side from the row's crossings, found once a row (as sample() does).
      if (s.kind_ == Shape::Kind::Mesh) s.mesh_->crossings(y, z, xs);
      for (std::size_t i = 0; i < row; ++i) {
        const P3 p{origin[0] + double(i) * pitch, y, z};
        Side side;
        if (s.kind_ == Shape::Kind::Mesh) {
          const auto above = std::upper_bound(xs.begin(), xs.end(), p[0]);
          const double eps = s.mesh_->on_surface();
          const bool on = above != xs.begin() && *(above - 1) == p[0];
          side.distance = on ? 0 : s.mesh_->distance(p, std::max(band, eps));
          side.sign = on || side.distance <= eps ? 0 : ((xs.end() - above) % 2 ? -1 : 1);
        } else {
          side = s.classify(p, band);
        }
        const double d = side.sign == 0 ? 0 : std::min(side.distance, band);
        out[r * row + i] = side.sign < 0 ? -d : d;
      }
    }
  });
  return out;
}

}  // namespace cellsph::geometry
