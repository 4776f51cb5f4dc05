#include "cellsph/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/core/format.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/render/bitmap_font.hpp"

namespace cellsph {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct V3 {
  double x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V3 operator-(V3 a, V3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V3 operator*(double s, V3 a) {
  return {s * a.x, s * a.y, s * a.z};
}
double dot(V3 a, V3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 normalized(V3 a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? (1 / n) * a : a;
}
V3 to_v3(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

// Pinhole or parallel projection onto the (supersampled) frame buffer. View coordinates: right, up,
// and depth along the viewing direction (positive in front of the camera).
struct View {
  V3 eye, right, up, fwd;
  bool ortho = false;
  double focal = 1;       // perspective: pixels per unit of (lateral / depth); ortho: pixels per world unit
  double cx = 0, cy = 0;  // screen position of the optical axis
  double near = 1e-9;

  [[nodiscard]] V3 to_view(V3 p) const {
    const V3 d = p - eye;
    return {dot(d, right), dot(d, up), dot(d, fwd)};
  }
  // Screen position (x right, y down) and depth of a view-space point.
  [[nodiscard]] bool project(V3 v, double& sx, double& sy) const {
    if (ortho) {
      sx = cx + focal * v.x;
      sy = cy - focal * v.y;
      return true;
    }
    if (v.z <= near) return false;
    sx = cx + focal * v.x / v.z;
    sy = cy - focal * v.y / v.z;
    return true;
  }
  [[nodiscard]] double pixel_radius(double r, double depth) const {
    return ortho ? focal * r : focal * r / depth;
  }
};

struct Sprite {
  V3 centre;
  double radius;
  Rgb8 colour;
};

struct FrameBuffer {
  int w, h;
  std::vector<float> rgb;
  std::vector<float> depth;
  FrameBuffer(int width, int height, Rgb8 bg)
      : w(width),
        h(height),
        rgb(3 * static_cast<std::size_t>(width) * height),
        depth(static_cast<std::size_t>(width) * height, std::numeric_limits<float>::infinity()) {
    for (std::size_t i = 0; i < rgb.size(); i += 3)
      for (int k = 0; k < 3; ++k) rgb[i + k] = static_cast<float>(bg[k]);
  }
};

// A sprite placed on the screen.
struct Placed {
  double sx, sy, rp, depth, radius;
  Rgb8 colour;
  int y0, y1;  // rows covered
};

// One directional light fixed to the camera (upper left, in front), Lambert plus a Blinn highlight.
// Sprites are drawn front to back (fewer shaded pixels that a nearer one would overwrite) and the frame
// is cut into bands of rows shaded in parallel; every pixel sees the sprites in the same order whatever
// the thread count, so the image is deterministic.
void shade_sprites(FrameBuffer& fb, const View& view, const std::vector<Sprite>& sprites) {
  std::vector<Placed> placed;
  placed.reserve(sprites.size());
  for (const auto& s : sprites) {
    const V3 c = view.to_view(s.centre);
    double sx, sy;
    if (!view.project(c, sx, sy)) continue;
    const double rp = std::max(0.75, view.pixel_radius(s.radius, c.z));
    if (sx + rp < 0 || sx - rp > fb.w || sy + rp < 0 || sy - rp > fb.h) continue;
    const int y0 = std::max(0, static_cast<int>(std::floor(sy - rp)));
    const int y1 = std::min(fb.h - 1, static_cast<int>(std::ceil(sy + rp)));
    placed.push_back({sx, sy, rp, c.z, s.radius, s.colour, y0, y1});
  }
  std::stable_sort(placed.begin(), placed.end(),
                   [](const Placed& a, const Placed& b) { return a.depth < b.depth; });

  const V3 light = normalized({-0.45, 0.65, -0.6});
  const V3 half = normalized(light + V3{0, 0, -1});
  constexpr int band = 32;
  const auto bands = static_cast<std::size_t>((fb.h + band - 1) / band);
  parallel_chunks(bands, 1, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t bi = b0; bi < b1; ++bi) {
      const int row0 = static_cast<int>(bi) * band, row1 = std::min(fb.h - 1, row0 + band - 1);
      for (const auto& s : placed) {
        if (s.y1 < row0 || s.y0 > row1) continue;
        const int x0 = std::max(0, static_cast<int>(std::floor(s.sx - s.rp)));
        const int x1 = std::min(fb.w - 1, static_cast<int>(std::ceil(s.sx + s.rp)));
        const double inv = 1 / s.rp;
        for (int y = std::max(row0, s.y0); y <= std::min(row1, s.y1); ++y) {
          const double dy = (s.sy - (y + 0.5)) * inv;
          for (int x = x0; x <= x1; ++x) {
            const double dx = (x + 0.5 - s.sx) * inv;
            const double q = dx * dx + dy * dy;
            if (q > 1) continue;
            const double nz = std::sqrt(1 - q);
            // Depth of the sphere's front surface at this pixel: the impostor behaves like a real
            // sphere where particles overlap.
            const auto d = static_cast<float>(s.depth - s.radius * nz);
            const std::size_t idx = static_cast<std::size_t>(y) * fb.w + x;
            if (!(d < fb.depth[idx])) continue;
            fb.depth[idx] = d;
            const V3 n{dx, dy, -nz};
            const double diffuse = std::max(0.0, dot(n, light));
            const double h1 = std::max(0.0, dot(n, half)), h2 = h1 * h1, h4 = h2 * h2, h8 = h4 * h4;
            const double spec = h8 * h8 * h8 * h8 * h8;  // exponent 40
            for (int k = 0; k < 3; ++k) {
              const double v = s.colour[k] * (0.3 + 0.7 * diffuse) + 90.0 * spec;
              fb.rgb[3 * idx + k] = static_cast<float>(std::min(255.0, v));
            }
          }
        }
      }
    }
  });
}

// A world-space segment, `thickness` pixels wide; depth-tested unless depth_test is false.
void draw_segment(FrameBuffer& fb, const View& view, V3 a, V3 b, double thickness, Rgb8 colour,
                  bool depth_test, double bias) {
  V3 va = view.to_view(a), vb = view.to_view(b);
  if (!view.ortho) {  // clip against the near plane
    const double nearz = 1e-6;
    if (va.z < nearz && vb.z < nearz) return;
    if (va.z < nearz) va = va + ((nearz - va.z) / (vb.z - va.z)) * (vb - va);
    if (vb.z < nearz) vb = vb + ((nearz - vb.z) / (va.z - vb.z)) * (va - vb);
  }
  double ax, ay, bx, by;
  if (!view.project(va, ax, ay) || !view.project(vb, bx, by)) return;
  const double len = std::hypot(bx - ax, by - ay);
  const int steps = std::min(100000, static_cast<int>(std::ceil(len * 2)) + 1);
  const double r = thickness / 2;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    const V3 v = va + t * (vb - va);
    double sx, sy;
    if (!view.project(v, sx, sy)) continue;
    const auto d = static_cast<float>(v.z - bias);
    for (int y = static_cast<int>(std::floor(sy - r)); y <= static_cast<int>(std::ceil(sy + r)); ++y) {
      for (int x = static_cast<int>(std::floor(sx - r)); x <= static_cast<int>(std::ceil(sx + r)); ++x) {
        if (x < 0 || y < 0 || x >= fb.w || y >= fb.h) continue;
        const double ddx = x + 0.5 - sx, ddy = y + 0.5 - sy;
        if (ddx * ddx + ddy * ddy > r * r) continue;
        const std::size_t idx = static_cast<std::size_t>(y) * fb.w + x;
        if (depth_test && !(d < fb.depth[idx])) continue;
        for (int k = 0; k < 3; ++k) fb.rgb[3 * idx + k] = colour[k];
      }
    }
  }
}

Image downsample(const FrameBuffer& fb, int ss) {
  Image img(fb.w / ss, fb.h / ss);
  const double inv = 1.0 / (ss * ss);
  parallel_for(static_cast<std::size_t>(img.height), [&](std::size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < img.width; ++x) {
      double acc[3] = {0, 0, 0};
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const std::size_t idx = static_cast<std::size_t>(y * ss + j) * fb.w + (x * ss + i);
          for (int k = 0; k < 3; ++k) acc[k] += static_cast<double>(fb.rgb[3 * idx + k]);
        }
      img.set(x, y,
              {static_cast<std::uint8_t>(std::lround(std::clamp(acc[0] * inv, 0.0, 255.0))),
               static_cast<std::uint8_t>(std::lround(std::clamp(acc[1] * inv, 0.0, 255.0))),
               static_cast<std::uint8_t>(std::lround(std::clamp(acc[2] * inv, 0.0, 255.0)))});
    }
  });
  return img;
}

// 1, 2 or 5 times a power of ten, at most `x`.
double nice_length(double x) {
  if (!(x > 0) || !std::isfinite(x)) return 0;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (const double m : {5.0, 2.0, 1.0})
    if (m * p <= x) return m * p;
  return p;
}

// Screen layout at final resolution: margins keep labels and legend off the particles.
struct Layout {
  int font = 1;
  int margin = 8;
  int left = 0, top = 0, right = 0, bottom = 0;  // the plot area [left, right) x [top, bottom)
};

Layout make_layout(const RenderOptions& o) {
  Layout l;
  l.font = std::max(1, static_cast<int>(std::lround(o.height / 360.0)));
  l.margin = 6 * l.font;
  const int text_h = text_height(l.font);
  l.left = l.margin;
  l.top = l.margin + (o.time_label ? text_h + l.margin : 0);
  l.bottom = o.height - l.margin - (o.scale_bar ? text_h + 6 * l.font + l.margin : 0);
  l.right = o.width - l.margin - (o.legend ? 12 * l.font + 4 * l.font + 13 * kGlyphAdvance * l.font : 0);
  if (l.right - l.left < o.width / 3 || l.bottom - l.top < o.height / 3) {  // tiny images: no reserve
    l.left = l.top = 0;
    l.right = o.width;
    l.bottom = o.height;
  }
  return l;
}

struct ViewAndScale {
  View view;
  double world_per_pixel = 0;  // at the target depth, final resolution
};

// 2D: a parallel projection along -z that fits the box into the plot area.
void fit_view_2d(ViewAndScale& r, V3 lo, V3 hi, double plot_w, double plot_h, int ss) {
  View& v = r.view;
  V3 centre = 0.5 * (lo + hi);
  centre.z = 0;
  v.ortho = true;
  v.fwd = {0, 0, -1};
  v.up = {0, 1, 0};
  v.right = cross(v.fwd, v.up);
  v.eye = centre + V3{0, 0, 1};
  const double bw = std::max(hi.x - lo.x, 1e-30), bh = std::max(hi.y - lo.y, 1e-30);
  const double scale = 0.96 * std::min(plot_w / bw, plot_h / bh);  // pixels per metre, final resolution
  v.focal = ss * scale;
  r.world_per_pixel = 1 / scale;
}

// 3D without a camera of the options': a perspective camera looking at the box's centre from a fixed
// direction (above and in front for either up axis), at the closest distance at which all eight box
// corners project into the plot area (bisection; the bounding sphere's distance always fits). (cx, cy):
// the plot area's centre on the supersampled screen.
Camera fitted_camera(const RenderOptions& o, V3 lo, V3 hi, double radius, const Layout& l, double cx,
                     double cy) {
  const int ss = o.supersample;
  const V3 centre = 0.5 * (lo + hi);
  const double plot_w = l.right - l.left, plot_h = l.bottom - l.top;
  Camera cam;
  cam.target = {centre.x, centre.y, centre.z};
  V3 dir = o.up_axis == 2 ? V3{0.55, -1.0, 0.5} : V3{0.55, 0.5, 1.0};
  cam.up = o.up_axis == 2 ? std::array<double, 3>{0, 0, 1} : std::array<double, 3>{0, 1, 0};
  const double focal = ss * (o.height / 2.0) / std::tan(cam.fov_y_deg * kPi / 360);
  View probe;
  probe.fwd = -1.0 * normalized(dir);
  probe.right = normalized(cross(probe.fwd, to_v3(cam.up)));
  probe.up = cross(probe.right, probe.fwd);
  probe.focal = focal;
  probe.cx = cx;
  probe.cy = cy;
  auto fits = [&](double dist) {
    probe.eye = centre + dist * normalized(dir);
    for (int i = 0; i < 8; ++i) {
      const V3 c{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
      double sx, sy;
      if (!probe.project(probe.to_view(c), sx, sy)) return false;
      if (sx < ss * (l.left + 0.02 * plot_w) || sx > ss * (l.right - 0.02 * plot_w) ||
          sy < ss * (l.top + 0.02 * plot_h) || sy > ss * (l.bottom - 0.02 * plot_h))
        return false;
    }
    return true;
  };
  double far = radius / std::sin(std::atan(std::min(plot_w, plot_h) / 2 * ss / focal)), close = radius;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (close + far);
    (fits(mid) ? far : close) = mid;
  }
  const V3 eye = centre + far * normalized(dir);
  cam.position = {eye.x, eye.y, eye.z};
  return cam;
}

// Looks through `cam` (each fault of it an InputError saying which) and sets the scale: an orthographic
// camera's height, or where it has none, the bounding sphere's diameter times `fit` (with a margin); a
// perspective camera's field of view.
void look_through(ViewAndScale& r, const Camera& cam, const RenderOptions& o, double radius, double fit) {
  const int ss = o.supersample;
  View& v = r.view;
  v.eye = to_v3(cam.position);
  v.fwd = normalized(to_v3(cam.target) - v.eye);
  if (!(dot(v.fwd, v.fwd) > 0)) throw InputError("render camera: position equals target");
  v.right = normalized(cross(v.fwd, to_v3(cam.up)));
  if (!(dot(v.right, v.right) > 0))
    throw InputError("render camera: up vector is zero or parallel to the viewing direction");
  if (!cam.orthographic && !(cam.fov_y_deg > 0 && cam.fov_y_deg < 180))
    throw InputError("render camera: field of view " + format_number("%g", cam.fov_y_deg) +
                     " degrees is outside (0, 180)");
  if (cam.orthographic && cam.ortho_height < 0)
    throw InputError("render camera: orthographic height " + format_number("%g", cam.ortho_height) +
                     " is negative");
  v.up = cross(v.right, v.fwd);
  v.ortho = cam.orthographic;
  const double target_dist = std::sqrt(dot(to_v3(cam.target) - v.eye, to_v3(cam.target) - v.eye));
  if (v.ortho) {
    double height = cam.ortho_height;
    if (!(height > 0)) height = 2 * radius * fit * 1.02;
    const double scale = o.height / height;
    v.focal = ss * scale;
    r.world_per_pixel = 1 / scale;
  } else {
    const double focal = (o.height / 2.0) / std::tan(cam.fov_y_deg * kPi / 360);
    v.focal = ss * focal;
    r.world_per_pixel = target_dist / focal;
  }
}

ViewAndScale make_view(int dim, const RenderOptions& o, const RenderBox& box, const Layout& l) {
  const int ss = o.supersample;
  const V3 lo = to_v3(box.lo), hi = to_v3(box.hi);
  const double plot_w = l.right - l.left, plot_h = l.bottom - l.top;
  ViewAndScale r;
  View& v = r.view;
  v.cx = ss * (l.left + plot_w / 2);
  v.cy = ss * (l.top + plot_h / 2);
  if (dim == 2) {
    fit_view_2d(r, lo, hi, plot_w, plot_h, ss);
    return r;
  }
  const V3 diag = hi - lo;
  const double radius = std::max(0.5 * std::sqrt(dot(diag, diag)), 1e-30);
  if (o.camera) {
    v.cx = ss * o.width / 2.0;  // an explicit camera looks through the image centre
    v.cy = ss * o.height / 2.0;
    look_through(r, *o.camera, o, radius, 1.0);
  } else {
    look_through(r, fitted_camera(o, lo, hi, radius, l, v.cx, v.cy), o, radius,
                 o.height / std::min(plot_w, plot_h));
  }
  return r;
}

void box_edges(int dim, const RenderBox& box, std::vector<std::pair<V3, V3>>& edges) {
  const V3 lo = to_v3(box.lo), hi = to_v3(box.hi);
  if (dim == 2) {
    const V3 a{lo.x, lo.y, 0}, b{hi.x, lo.y, 0}, c{hi.x, hi.y, 0}, d{lo.x, hi.y, 0};
    edges = {{a, b}, {b, c}, {c, d}, {d, a}};
    return;
  }
  auto corner = [&](int i) {
    return V3{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
  };
  for (int i = 0; i < 8; ++i)
    for (int bit = 1; bit < 8; bit <<= 1)
      if (!(i & bit)) edges.emplace_back(corner(i), corner(i | bit));
}

const Rgb8 kInk{25, 25, 25};

void draw_label(Image& img, int x, int y, const std::string& text, int font, Rgb8 bg) {
  img.fill_rect(x - font, y - font, x + text_width(text, font) + font, y + text_height(font) + font, bg,
                0.75);
  draw_text(img, x, y, text, kInk, font);
}

// The range the colour map spans (the visible particles' finite values, or the options' bounds) and the
// phases the visible particles hold.
struct ColourRange {
  double vmin = 0, vmax = 0, span = 1;
  std::set<int> phases;
};

void draw_box_outline(FrameBuffer& fb, const View& view, int dim, const RenderBox& box, double thickness) {
  std::vector<std::pair<V3, V3>> edges;
  box_edges(dim, box, edges);
  const V3 diag = to_v3(box.hi) - to_v3(box.lo);
  const double bias = 1e-3 * std::sqrt(dot(diag, diag));
  for (const auto& [a, b] : edges) draw_segment(fb, view, a, b, thickness, {70, 70, 70}, dim == 3, bias);
}

// A bar of a round length at the bottom left; `at_target`: the length holds at the target's depth only.
void draw_scale_bar(Image& img, const RenderOptions& o, const Layout& layout, double world_per_pixel,
                    bool at_target) {
  const int f = layout.font, m = layout.margin, th = text_height(f);
  const double len = nice_length(world_per_pixel * o.width / 6);
  const int px = static_cast<int>(std::lround(len / world_per_pixel));
  const int y = o.height - m - 2 * f;
  img.fill_rect(m, y, m + px, y + 2 * f, kInk);
  img.fill_rect(m, y - 3 * f, m + f, y + 2 * f, kInk);
  img.fill_rect(m + px - f, y - 3 * f, m + px, y + 2 * f, kInk);
  const std::string label = format_number("%g", len) + " m" + (at_target ? " at target" : "");
  draw_label(img, m + 2 * f, y - 4 * f - th, label, f, o.background);
}

// At the top right: the colour of each phase shown (at most 8), or the colour bar with its range.
void draw_legend(Image& img, const RenderOptions& o, const Layout& layout, const ColourRange& range) {
  const int f = layout.font, m = layout.margin, th = text_height(f);
  const int x = o.width - m - 13 * kGlyphAdvance * f - 16 * f;
  int y = m;
  if (o.color_by == ColorBy::Phase) {
    int shown = 0;
    for (const int ph : range.phases) {
      if (++shown > 8) break;
      img.fill_rect(x, y, x + th, y + th, phase_colour(ph));
      draw_text(img, x + th + 4 * f, y, "phase " + std::to_string(ph), kInk, f);
      y += th + 4 * f;
    }
    return;
  }
  draw_text(img, x, y, o.color_by == ColorBy::Speed ? "speed [m/s]" : "pressure [Pa]", kInk, f);
  y += th + 4 * f;
  const int bar_h = o.height / 3, bar_w = 12 * f;
  for (int j = 0; j < bar_h; ++j) {
    const Rgb8 c = colormap(1.0 - static_cast<double>(j) / std::max(1, bar_h - 1));
    img.fill_rect(x, y + j, x + bar_w, y + j + 1, c);
  }
  draw_text(img, x + bar_w + 4 * f, y, format_number("%.3g", range.vmax), kInk, f);
  draw_text(img, x + bar_w + 4 * f, y + bar_h - th, format_number("%.3g", range.vmin), kInk, f);
}

void check_render_options(const RenderOptions& o) {
  if (!(o.width > 0 && o.height > 0 && o.width <= 16384 && o.height <= 16384))
    throw InputError("render image size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                     " is outside 1..16384");
  if (!(o.supersample >= 1 && o.supersample <= 4))
    throw InputError("render supersample " + std::to_string(o.supersample) + " is outside 1..4");
  if (o.up_axis != 1 && o.up_axis != 2)
    throw InputError("render up axis " + std::to_string(o.up_axis) + " must be 1 (y) or 2 (z)");
}

// The scalar particle i is coloured by (0 when colouring by phase).
template <int Dim, class Real>
double colour_value(const Particles<Dim, Real>& p, const RenderOptions& o, std::size_t i) {
  if (o.color_by == ColorBy::Speed) return std::sqrt(static_cast<double>(norm2(p.v[i])));
  if (o.color_by == ColorBy::Pressure) return static_cast<double>(p.p[i]);
  return 0;
}

template <int Dim, class Real>
ColourRange colour_range(const Particles<Dim, Real>& p, const RenderOptions& o) {
  const auto n = p.size();
  double vmin = std::numeric_limits<double>::infinity(), vmax = -vmin;
  ColourRange r;
  for (std::size_t i = 0; i < n; ++i) {
    if ((o.visible && !o.visible(i)) || (o.solid && o.solid(i))) continue;
    r.phases.insert(p.phase[i]);
    const double v = colour_value(p, o, i);
    if (std::isfinite(v)) {
      vmin = std::min(vmin, v);
      vmax = std::max(vmax, v);
    }
  }
  if (o.range_min) vmin = *o.range_min;
  if (o.range_max) vmax = *o.range_max;
  if (!std::isfinite(vmin) || !std::isfinite(vmax)) vmin = vmax = 0;
  r.vmin = vmin;
  r.vmax = vmax;
  r.span = vmax > vmin ? vmax - vmin : 1;
  return r;
}

template <int Dim, class Real>
double particle_radius(const Particles<Dim, Real>& p, const RenderOptions& o, std::size_t i,
                       double fallback) {
  if (o.particle_radius > 0) return o.particle_radius;
  const double m = static_cast<double>(p.m[i]), rho = static_cast<double>(p.rho[i]);
  return m > 0 && rho > 0 ? 0.5 * std::pow(m / rho, 1.0 / Dim)
                          : (p.h[i] > 0 ? static_cast<double>(p.h[i]) / 4 : fallback);
}

// Whether a solid at c lies outside the box on a side whose outside holds the eye: a near wall in 3D.
bool cut_away(V3 c, const RenderBox& box, V3 eye) {
  const double x[3] = {c.x, c.y, c.z}, e[3] = {eye.x, eye.y, eye.z};
  for (std::size_t a = 0; a < 3; ++a)
    if ((x[a] < box.lo[a] && e[a] < box.lo[a]) || (x[a] > box.hi[a] && e[a] > box.hi[a])) return true;
  return false;
}

// One disc per visible particle: its radius the options' or half its volume's edge (else a quarter of h,
// else a 400th of the box's diagonal), its colour its phase's or the colour map's, a solid's grey.
template <int Dim, class Real>
std::vector<Sprite> make_sprites(const Particles<Dim, Real>& p, const RenderOptions& o, const RenderBox& box,
                                 const ColourRange& range, const View& view) {
  const auto n = p.size();
  const V3 diag = to_v3(box.hi) - to_v3(box.lo);
  const double fallback_radius = std::sqrt(dot(diag, diag)) / 400;
  std::vector<Sprite> sprites;
  sprites.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (o.visible && !o.visible(i)) continue;
    Sprite s;
    s.centre = {static_cast<double>(p.x[i][0]), static_cast<double>(p.x[i][1]),
                Dim == 3 ? static_cast<double>(p.x[i][Dim - 1]) : 0.0};
    if (o.solid && o.solid(i)) {
      if (Dim == 3 && cut_away(s.centre, box, view.eye)) continue;
      s.colour = kSolidColour;
      s.radius = o.solid_radius > 0 ? o.solid_radius : particle_radius(p, o, i, fallback_radius);
      sprites.push_back(s);
      continue;
    }
    s.radius = particle_radius(p, o, i, fallback_radius);
    s.colour = o.color_by == ColorBy::Phase ? phase_colour(p.phase[i])
                                            : colormap((colour_value(p, o, i) - range.vmin) / range.span);
    sprites.push_back(s);
  }
  return sprites;
}

}  // namespace

ColorBy parse_color_by(std::string_view name, std::string_view what) {
  if (name == "phase") return ColorBy::Phase;
  if (name == "speed") return ColorBy::Speed;
  if (name == "pressure") return ColorBy::Pressure;
  throw InputError(std::string(what) + ": unknown colouring '" + std::string(name) +
                   "' (expected phase, speed or pressure)");
}

Rgb8 phase_colour(int phase) {
  static constexpr Rgb8 palette[8] = {{40, 110, 220}, {240, 140, 30}, {50, 170, 80},   {210, 50, 50},
                                      {150, 90, 200}, {140, 90, 50},  {230, 110, 180}, {20, 170, 180}};
  if (phase < 0) return {150, 150, 150};
  return palette[phase % 8];
}

Rgb8 colormap(double t) {
  static constexpr double stops[5][3] = {
      {20, 30, 120}, {30, 110, 230}, {50, 200, 210}, {240, 220, 50}, {210, 40, 30}};
  if (!std::isfinite(t)) t = 0;
  t = std::clamp(t, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(t));
  const double f = t - i;
  Rgb8 c;
  for (int k = 0; k < 3; ++k)
    c[k] = static_cast<std::uint8_t>(std::lround((1 - f) * stops[i][k] + f * stops[i + 1][k]));
  return c;
}

template <int Dim, class Real>
Image render_image(const Particles<Dim, Real>& p, const RenderOptions& o, const RenderBox& box, double time) {
  check_render_options(o);
  const int ss = o.supersample;
  const Layout layout = make_layout(o);
  const ViewAndScale vs = make_view(Dim, o, box, layout);

  const auto n = p.size();
  CELLSPH_CHECK(p.v.size() == n && p.p.size() == n && p.m.size() == n && p.rho.size() == n &&
                    p.h.size() == n && p.phase.size() == n,
                "particle fields of unequal length");
  const ColourRange range = colour_range(p, o);
  const std::vector<Sprite> sprites = make_sprites(p, o, box, range, vs.view);

  FrameBuffer fb(o.width * ss, o.height * ss, o.background);
  shade_sprites(fb, vs.view, sprites);
  if (o.box_outline) draw_box_outline(fb, vs.view, Dim, box, ss * std::max(2.0, 1.1 * layout.font));
  Image img = downsample(fb, ss);

  // Overlays at final resolution.
  const int f = layout.font, m = layout.margin;
  if (o.time_label) draw_label(img, m, m, "t = " + format_number("%.3f", time) + " s", f, o.background);
  if (o.scale_bar && vs.world_per_pixel > 0)
    draw_scale_bar(img, o, layout, vs.world_per_pixel, Dim == 3 && !vs.view.ortho);
  if (o.legend) draw_legend(img, o, layout, range);
  return img;
}

template <int Dim, class Real>
void render_png(const Particles<Dim, Real>& particles, const RenderOptions& options, const RenderBox& box,
                double time, const std::filesystem::path& path) {
  write_png(render_image(particles, options, box, time), path);
}

#define CELLSPH_RENDER_INSTANTIATE(D, R)                                                                     \
  template Image render_image<D, R>(const Particles<D, R>&, const RenderOptions&, const RenderBox&, double); \
  template void render_png<D, R>(const Particles<D, R>&, const RenderOptions&, const RenderBox&, double,     \
                                 const std::filesystem::path&);
CELLSPH_RENDER_INSTANTIATE(2, float)
CELLSPH_RENDER_INSTANTIATE(2, double)
CELLSPH_RENDER_INSTANTIATE(3, float)
CELLSPH_RENDER_INSTANTIATE(3, double)
#undef CELLSPH_RENDER_INSTANTIATE

}  // namespace cellsph
