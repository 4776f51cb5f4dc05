// Geometry the particle spacing resolves poorly, said when the scene loads (issue 52 item 5): a gap
// under two spacings holds at most one row of fluid particles, which the kernel sees as a film; a solid
// thinner than the kernel support gives the fluid beside it fewer wall neighbours than a wall of full
// depth, so its pressure pushes back too weakly. Box obstacles and the tank's box walls are checked
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
  return out;
}

template std::vector<std::string> geometry_warnings<2>(const Regions<2>&, double, double);
template std::vector<std::string> geometry_warnings<3>(const Regions<3>&, double, double);

}  // namespace cellsph::scene_detail
