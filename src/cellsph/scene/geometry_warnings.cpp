// Geometry the particle spacing resolves poorly, said when the scene loads (issue 52 item 5): a gap
// under two spacings holds at most one row of fluid particles, which the kernel sees as a film; a solid
// thinner than the kernel support gives the fluid beside it fewer wall neighbours than a wall of full
// depth, so its pressure pushes back too weakly; a fluid block thinner than the support has no particle
// whose kernel lies inside it. Box obstacles and the tank's box walls are checked
// exactly; shaped obstacles (meshes, spheres, cylinders) are not.
#include <cstdio>

#include "cellsph/core/format.hpp"
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

std::string metres(double x) {
  return format_number("%.4g m", x);
}

std::string spacings(double x, double spacing) {
  return format_number("%.2g", x / spacing);
}

// The gap between two boxes that face each other along exactly one axis (their extents overlap on the
// others), and that axis; gap <= 0 where they overlap, touch or do not face each other.
template <int Dim>
std::pair<double, std::size_t> facing_gap(const Aabb<Dim>& a, const Aabb<Dim>& b) {
  double gap = 0;
  std::size_t axis = 0;
  int apart = 0;
  for (std::size_t k = 0; k < Dim; ++k) {
    const double sep = std::max(b.lo[k] - a.hi[k], a.lo[k] - b.hi[k]);
    if (sep >= 0) {
      ++apart;
      gap = sep;
      axis = k;
    }
  }
  return apart == 1 ? std::pair{gap, axis} : std::pair{0.0, std::size_t{0}};
}

std::string gap_warning(const std::string& a, const std::string& b, double gap, std::size_t axis,
                        double spacing) {
  return a + " and " + b + ": a gap of " + metres(gap) + " along " + kAxis[axis] + " (" +
         spacings(gap, spacing) + " spacings) holds under two rows of fluid particles; a finer /spacing " +
         "(at most " + metres(gap / 2) + ") resolves it";
}

// A solid for the shapes' checks: its signed distance (negative inside; exact up to `band`, beyond it
// band or more) and the box beyond which it is more than `band` away (none: unbounded, the tank's walls).
struct SolidDistance {
  std::string key;
  std::function<double(const geometry::P3&)> distance;
  std::optional<std::pair<geometry::P3, geometry::P3>> near;
};

template <int Dim>
SolidDistance shape_solid(const geometry::Shape& shape, const std::string& key, bool container, double band) {
  geometry::P3 lo = shape.lo(), hi = shape.hi();
  for (int a = 0; a < Dim; ++a) {
    lo[static_cast<std::size_t>(a)] -= band;
    hi[static_cast<std::size_t>(a)] += band;
  }
  return {key,
          [&shape, container, band](const geometry::P3& p) {
            const geometry::Side side = shape.classify(p, band);
            const double d = std::min(side.distance, band) * (side.sign < 0 ? -1 : 1);
            return container ? -d : d;
          },
          std::pair{lo, hi}};
}

template <int Dim>
SolidDistance box_solid(const Aabb<Dim>& b, const std::string& key, double band) {
  geometry::P3 lo{0, 0, 0}, hi{0, 0, 0};
  for (std::size_t a = 0; a < Dim; ++a) {
    lo[a] = b.lo[a] - band;
    hi[a] = b.hi[a] + band;
  }
  return {key,
          [b](const geometry::P3& p) {
            double out = 0, in = HUGE_VAL;
            for (std::size_t a = 0; a < Dim; ++a) {
              const double below = p[a] - b.lo[a], above = b.hi[a] - p[a];
              const double o = std::max(0.0, std::max(-below, -above));
              out += o * o;
              in = std::min(in, std::min(below, above));
            }
            return out > 0 ? std::sqrt(out) : -in;
          },
          std::pair{lo, hi}};
}

// The tank of boundary.walls as a solid: everything outside its box but its open top.
template <int Dim>
SolidDistance tank_solid(const Aabb<Dim>& b, int open_axis, const std::string& key) {
  return {key,
          [b, open_axis](const geometry::P3& p) {
            double in = HUGE_VAL;
            for (std::size_t a = 0; a < Dim; ++a) {
              in = std::min(in, p[a] - b.lo[a]);
              if (static_cast<int>(a) != open_axis) in = std::min(in, b.hi[a] - p[a]);
            }
            return in;
          },
          std::nullopt};
}

// The narrowest gap between solids a and b, sampled on a lattice `pitch` apart where both are within
// `band`: the least d_a + d_b over points outside both; none (0) where they touch or overlap (a point
// within a pitch of both surfaces).
template <int Dim>
double sampled_gap(const SolidDistance& a, const SolidDistance& b, double pitch, double band) {
  geometry::P3 lo{0, 0, 0}, hi{0, 0, 0};
  const auto& box = a.near ? a.near : b.near;
  if (!box) return 0;
  lo = box->first;
  hi = box->second;
  if (a.near && b.near)
    for (std::size_t k = 0; k < Dim; ++k) {
      lo[k] = std::max(lo[k], b.near->first[k]);
      hi[k] = std::min(hi[k], b.near->second[k]);
      if (!(lo[k] < hi[k])) return 0;
    }
  std::array<long, 3> n{1, 1, 1};
  for (std::size_t k = 0; k < Dim; ++k) n[k] = static_cast<long>(std::ceil((hi[k] - lo[k]) / pitch)) + 1;
  // The tank (unbounded) is the cheaper distance: test it first where it is one of the two.
  const bool b_first = !b.near;
  double gap = HUGE_VAL;
  for (long k = 0; k < n[2]; ++k)
    for (long j = 0; j < n[1]; ++j)
      for (long i = 0; i < n[0]; ++i) {
        const geometry::P3 p{lo[0] + double(i) * pitch, lo[1] + double(j) * pitch,
                             Dim == 3 ? lo[2] + double(k) * pitch : 0.0};
        const double d1 = (b_first ? b : a).distance(p);
        if (d1 >= band) continue;
        const double d2 = (b_first ? a : b).distance(p);
        if (d2 >= band) continue;
        if (std::max(d1, d2) < pitch) return 0;  // touching or overlapping
        if (d1 > 0 && d2 > 0) gap = std::min(gap, d1 + d2);
      }
  return std::isfinite(gap) ? gap : 0;
}

// An upper bound on how thick a shaped solid is where it is thickest, when that is under `support`
// (sampled `pitch` apart: twice the deepest inside point's depth plus a pitch); 0 where it is thicker.
template <int Dim>
double thin_shape(const geometry::Shape& shape, double support, double pitch) {
  std::array<long, 3> n{1, 1, 1};
  for (std::size_t k = 0; k < Dim; ++k)
    n[k] = static_cast<long>(std::ceil((shape.hi()[k] - shape.lo()[k]) / pitch)) + 1;
  double deepest = 0;
  for (long k = 0; k < n[2]; ++k)
    for (long j = 0; j < n[1]; ++j)
      for (long i = 0; i < n[0]; ++i) {
        const geometry::P3 p{shape.lo()[0] + double(i) * pitch, shape.lo()[1] + double(j) * pitch,
                             Dim == 3 ? shape.lo()[2] + double(k) * pitch : 0.0};
        const geometry::Side side = shape.classify(p, support);
        if (side.sign < 0) deepest = std::max(deepest, std::min(side.distance, support));
        if (2 * deepest + pitch >= support) return 0;
      }
  return 2 * deepest + pitch;
}

// The shapes' gaps (to each other, to box obstacles and to the tank's walls) and thin shapes.
template <int Dim>
void shape_warnings(const Regions<Dim>& regions, double spacing, double support,
                    std::vector<std::string>& out) {
  const double band = 2 * spacing;
  std::vector<SolidDistance> shapes, others;
  for (std::size_t i = 0; i < regions.all_shapes.size(); ++i) {
    const bool container = regions.shape_margins[i] > 0;
    shapes.push_back(shape_solid<Dim>(regions.all_shapes[i], regions.shape_keys[i], container, band));
    const double thick = container ? 0 : thin_shape<Dim>(regions.all_shapes[i], support, spacing / 2);
    if (thick > 0)
      out.push_back(regions.shape_keys[i] + ": at most " + metres(thick) +
                    " thick, thinner than the kernel support " + metres(support) +
                    ": the fluid beside it has fewer wall neighbours than at a full wall and may be pushed "
                    "through; make it at least " +
                    metres(support) + " thick");
  }
  for (std::size_t i = 0; i < regions.solids.size(); ++i)
    others.push_back(box_solid<Dim>(regions.solids[i], regions.solid_keys[i], band));
  if (!regions.container_key.empty() && regions.container)
    others.push_back(tank_solid<Dim>(*regions.container, regions.container_open_axis, regions.container_key));
  auto check = [&](const SolidDistance& a, const SolidDistance& b) {
    const double gap = sampled_gap<Dim>(a, b, spacing / 4, band);
    if (gap > 0 && gap < 2 * spacing)
      out.push_back(a.key + " and " + b.key + ": a gap of about " + metres(gap) + " (" +
                    spacings(gap, spacing) +
                    " spacings) holds under two rows of fluid particles; a finer /spacing (at most " +
                    metres(gap / 2) + ") resolves it");
  };
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    for (std::size_t j = i + 1; j < shapes.size(); ++j) check(shapes[i], shapes[j]);
    for (const auto& o : others) check(shapes[i], o);
  }
}

}  // namespace

template <int Dim>
std::vector<std::string> geometry_warnings(const Regions<Dim>& regions, double spacing, double support) {
  std::vector<std::string> out;
  const auto& s = regions.solids;
  for (std::size_t i = 0; i < s.size(); ++i) {
    for (std::size_t a = 0; a < Dim; ++a) {
      const double t = s[i].hi[a] - s[i].lo[a];
      if (t < support)
        out.push_back(regions.solid_keys[i] + ": " + metres(t) + " thick along " + kAxis[a] +
                      ", thinner than the kernel support " + metres(support) +
                      ": the fluid beside it has fewer wall neighbours than at a full wall and may be pushed "
                      "through; make it at least " +
                      metres(support) + " thick");
    }
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      const auto [gap, axis] = facing_gap<Dim>(s[i], s[j]);
      if (gap > 0 && gap < 2 * spacing)
        out.push_back(gap_warning(regions.solid_keys[i], regions.solid_keys[j], gap, axis, spacing));
    }
    if (!regions.container_key.empty() && regions.container)
      for (std::size_t a = 0; a < Dim; ++a)
        for (const double gap :
             {s[i].lo[a] - regions.container->lo[a], regions.container->hi[a] - s[i].hi[a]})
          if (gap > 0 && gap < 2 * spacing)
            out.push_back(gap_warning(regions.solid_keys[i], regions.container_key, gap, a, spacing));
  }
  shape_warnings(regions, spacing, support, out);
  return out;
}

template <int Dim>
std::vector<std::string> fluid_block_warnings(const FluidBlocks<Dim>& fluids, double support) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < fluids.blocks.size(); ++k)
    for (std::size_t a = 0; a < Dim; ++a) {
      const double t = fluids.blocks[k].hi[a] - fluids.blocks[k].lo[a];
      if (t < support)
        out.push_back("/fluids/" + std::to_string(fluids.key[k]) + ": " + metres(t) + " thick along " +
                      kAxis[a] + ", less than the kernel support " + metres(support) +
                      ": every particle's kernel spans the block, which then holds no interior to keep its "
                      "density (a free block this thin collapses); a finer /spacing with a smaller "
                      "/solver/support resolves it");
    }
  return out;
}

template std::vector<std::string> geometry_warnings<2>(const Regions<2>&, double, double);
template std::vector<std::string> geometry_warnings<3>(const Regions<3>&, double, double);

template std::vector<std::string> fluid_block_warnings<2>(const FluidBlocks<2>&, double);
template std::vector<std::string> fluid_block_warnings<3>(const FluidBlocks<3>&, double);

}  // namespace cellsph::scene_detail
