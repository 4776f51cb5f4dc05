// /output (docs/scenes.md, "output"): frames, checkpoints, pictures; and the box drawn in pictures.
#include "cellsph/scene/scene_readers.hpp"

#include <algorithm>
#include <limits>

namespace cellsph::scene_detail {

template <int Dim>
void read_output(JsonReader& r, OutputSettings& out) {
  if (!r.has("output")) {
    out.up_axis = Dim - 1;
    return;
  }
  auto orr = r.child("output");
  out.fps = orr.number("fps", out.fps, 1e-6, 1e6);
  if (orr.has("formats")) {
    const auto& fj = orr.json()["formats"];
    if (!fj.is_array()) orr.fail("formats", "expected an array of vtu, ply, csv, got " + json_value_text(fj));
    auto list = orr.child("formats");
    out.formats.clear();
    for (std::size_t k = 0; k < list.array_size(); ++k) {
      const auto& v = fj[k];
      if (!v.is_string() || (v != "vtu" && v != "ply" && v != "csv"))
        list.element(k).fail_here("unknown format " + json_value_text(v) + " (expected vtu, ply or csv)");
      out.formats.push_back(v.get<std::string>());
    }
  }
  out.checkpoint_every = static_cast<int>(orr.integer("checkpoint_every", out.checkpoint_every, 0, 1000000));
  out.color_by = orr.choice("color_by", out.color_by, {"phase", "speed", "pressure"});
  out.up_axis = static_cast<int>(orr.integer("up_axis", Dim - 1, 0, Dim - 1));
  orr.finish();
}

// The box drawn in pictures: the container, else the particles' bounds.
template <int Dim, class Real>
void set_view(Scene<Dim, Real>& s, const std::optional<Aabb<Dim>>& container) {
  std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
  const auto& p = s.particles;
  if (container) {
    for (std::size_t a = 0; a < Dim; ++a) {
      lo[a] = container->lo[a];
      hi[a] = container->hi[a];
    }
  } else {
    for (std::size_t a = 0; a < Dim; ++a) {
      lo[a] = std::numeric_limits<double>::max();
      hi[a] = std::numeric_limits<double>::lowest();
    }
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t a = 0; a < Dim; ++a) {
        lo[a] = std::min(lo[a], double(p.x[i][static_cast<int>(a)]));
        hi[a] = std::max(hi[a], double(p.x[i][static_cast<int>(a)]));
      }
  }
  s.view_lo = lo;
  s.view_hi = hi;
}

template void read_output<2>(JsonReader&, OutputSettings&);
template void read_output<3>(JsonReader&, OutputSettings&);

#define CELLSPH_VIEW_INSTANTIATE(D, R) \
  template void set_view<D, R>(Scene<D, R>&, const std::optional<Aabb<D>>&);
CELLSPH_VIEW_INSTANTIATE(2, float)
CELLSPH_VIEW_INSTANTIATE(2, double)
CELLSPH_VIEW_INSTANTIATE(3, float)
CELLSPH_VIEW_INSTANTIATE(3, double)
#undef CELLSPH_VIEW_INSTANTIATE

}  // namespace cellsph::scene_detail
