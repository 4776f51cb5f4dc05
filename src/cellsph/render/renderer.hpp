#pragma once
// Software renderer for frames like the paper's Figure 2: particles as shaded discs (2D) or
// depth-buffered sphere impostors (3D) under one directional light, coloured by phase, speed or
// pressure, with the domain box outline, a scale bar, a time label and a colour legend. No display,
// no GPU: a z-buffer on the CPU, 2x2 supersampled, then PNG.
#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "cellsph/render/image.hpp"
#include "cellsph/solver/particles.hpp"

namespace cellsph {

enum class ColorBy { Phase, Speed, Pressure };

// "phase", "speed" or "pressure"; throws InputError naming `what` (e.g. a scene key) otherwise.
ColorBy parse_color_by(std::string_view name, std::string_view what = "--color-by");

// The domain box [lo, hi]; z is ignored in 2D.
struct RenderBox {
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> hi{1, 1, 1};
};

// 3D camera. Perspective (vertical field of view) or orthographic (visible world height).
struct Camera {
  std::array<double, 3> position{0, 0, 5};
  std::array<double, 3> target{0, 0, 0};
  std::array<double, 3> up{0, 1, 0};
  double fov_y_deg = 35;  // perspective only
  bool orthographic = false;
  double ortho_height = 0;  // orthographic only: world units across the image height; 0 = frame the box
};

struct RenderOptions {
  int width = 1280;
  int height = 720;
  ColorBy color_by = ColorBy::Phase;
  // 3D camera; unset = look at the box centre from the front-right-above, framing the whole box.
  // 2D always uses a fitted orthographic top view.
  std::optional<Camera> camera;
  int up_axis = 1;             // world axis that points up in the default 3D camera (1 = y, 2 = z)
  double particle_radius = 0;  // world units; 0 = half the spacing (m/rho)^(1/Dim) of each particle
  std::optional<double> range_min, range_max;  // colour-map range for speed/pressure; unset = data range
  int supersample = 2;                         // samples per pixel along each axis
  bool box_outline = true;
  bool scale_bar = true;
  bool time_label = true;
  bool legend = true;
  Rgb8 background{250, 250, 250};
  // Which particles are drawn; empty = all (e.g. hide boundary particles). Called serially.
  std::function<bool(std::size_t)> visible;
  // Which visible particles are solids (walls, obstacles, floating bodies): drawn in a neutral grey,
  // shaded as the fluid, and left out of the colour range and the legend; empty = none. In 3D the
  // solids outside the box on a side that faces the camera (a tank's near walls and lid) are cut away,
  // so that the view into the box stays open; its floor and far walls stay. Called serially.
  std::function<bool(std::size_t)> solid;
  double solid_radius = 0;  // world units; 0 = as for the fluid
};

// The neutral colour of solids.
inline constexpr Rgb8 kSolidColour{176, 174, 168};

// Fixed palette: the colour of phase `phase` (cycled after 8; negative phases are grey).
Rgb8 phase_colour(int phase);
// The colour map for speed and pressure, t in [0, 1] (clamped): dark blue, blue, cyan, yellow, red.
Rgb8 colormap(double t);

template <int Dim, class Real>
Image render_image(const Particles<Dim, Real>& particles, const RenderOptions& options, const RenderBox& box,
                   double time);

// Renders and writes a PNG atomically.
template <int Dim, class Real>
void render_png(const Particles<Dim, Real>& particles, const RenderOptions& options, const RenderBox& box,
                double time, const std::filesystem::path& path);

}  // namespace cellsph
