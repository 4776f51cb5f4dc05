#include "cellsph/render/renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellsph/core/error.hpp"
#include "cellsph/core/parallel.hpp"
#include "cellsph/io/io_test_util.hpp"
#include "cellsph/render/bitmap_font.hpp"
#include "cellsph/render/video.hpp"

namespace cellsph {
namespace {

// Colour classes judged from the pixel alone, independent of the renderer's palette code.
bool bluish(Rgb8 c) {
  return c[2] > c[0] + 40 && c[2] > c[1] + 20;
}
bool orangeish(Rgb8 c) {
  return c[0] > c[2] + 60 && c[0] > c[1];
}
bool dark_grey(Rgb8 c) {
  const int mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
  return mx < 140 && mx - mn < 12;
}
const Rgb8 kBackground{250, 250, 250};

template <int Dim>
Particles<Dim, double> make_scene(const std::vector<std::pair<Vec<Dim, double>, int>>& spec) {
  Particles<Dim, double> p;
  p.resize(spec.size());
  for (std::size_t i = 0; i < spec.size(); ++i) {
    p.x[i] = spec[i].first;
    p.phase[i] = spec[i].second;
    p.m[i] = 1;
    p.rho[i] = 1000;
  }
  return p;
}

RenderOptions bare(int w, int h) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.time_label = o.scale_bar = o.legend = false;
  o.background = kBackground;
  return o;
}

TEST(Renderer, TwoDimensionalDiscsSitWhereTheParticlesAre) {
  const auto p = make_scene<2>({{Vec<2, double>{{0.5, 0.5}}, 0}, {Vec<2, double>{{1.5, 0.5}}, 1}});
  RenderOptions o = bare(400, 240);
  o.particle_radius = 0.08;
  const RenderBox box{{0, 0, 0}, {2, 1, 0}};
  const Image img = render_image(p, o, box, 0.0);
  ASSERT_EQ(img.width, 400);
  ASSERT_EQ(img.height, 240);

  // Locate the drawn box outline: the only grey ink in this picture.
  int x0 = img.width, x1 = -1, y0 = img.height, y1 = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (dark_grey(img.at(x, y))) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
  ASSERT_GT(x1 - x0, img.width / 2) << "box outline not found";
  EXPECT_NEAR(static_cast<double>(x1 - x0) / (y1 - y0), 2.0, 0.05) << "aspect ratio not preserved";
  // World to pixel from the outline alone (y up in the world, down in the image).
  const double sx = (x1 - x0) / 2.0, sy = (y1 - y0) / 1.0;
  auto px = [&](double wx) { return static_cast<int>(std::lround(x0 + 0.5 + wx * sx)); };
  auto py = [&](double wy) { return static_cast<int>(std::lround(y1 + 0.5 - wy * sy)); };
  const double r = 0.08 * sx;  // radius in pixels

  EXPECT_TRUE(bluish(img.at(px(0.5), py(0.5))));
  EXPECT_TRUE(orangeish(img.at(px(1.5), py(0.5))));
  for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
    const int ox = static_cast<int>(std::lround(0.6 * r * dx)),
              oy = static_cast<int>(std::lround(0.6 * r * dy));
    EXPECT_TRUE(bluish(img.at(px(0.5) + ox, py(0.5) + oy))) << dx << "," << dy;
    EXPECT_TRUE(orangeish(img.at(px(1.5) + ox, py(0.5) + oy))) << dx << "," << dy;
    const int fx = static_cast<int>(std::lround(1.4 * r * dx)),
              fy = static_cast<int>(std::lround(1.4 * r * dy));
    EXPECT_EQ(img.at(px(0.5) + fx, py(0.5) + fy), kBackground) << dx << "," << dy;
    EXPECT_EQ(img.at(px(1.5) + fx, py(0.5) + fy), kBackground) << dx << "," << dy;
  }
  EXPECT_EQ(img.at(px(1.0), py(0.5)), kBackground);
  EXPECT_EQ(img.at(px(0.2), py(0.2)), kBackground);
  EXPECT_EQ(img.at(px(1.8), py(0.85)), kBackground);
  EXPECT_EQ(img.at(2, 2), kBackground);  // outside the box, no labels asked for

  // Disc areas: the coloured pixels cover about 2 pi r^2.
  int coloured = 0;
  for (int y = y0 + 3; y <= y1 - 3; ++y)
    for (int x = x0 + 3; x <= x1 - 3; ++x) coloured += img.at(x, y) != kBackground;
  EXPECT_NEAR(coloured, 2 * M_PI * r * r, 0.15 * 2 * M_PI * r * r);
}

TEST(Renderer, ThreeDimensionalOrthographicCameraAndDepthOrder) {
  // Camera looking down -z through the box centre: the image centre is (0.5, 0.5), 120 px per metre.
  RenderOptions o = bare(320, 240);
  o.camera = Camera{{0.5, 0.5, 5}, {0.5, 0.5, 0.5}, {0, 1, 0}, 35, true, 2.0};
  o.particle_radius = 0.1;
  const RenderBox box{{0, 0, 0}, {1, 1, 1}};
  for (const bool near_first : {true, false}) {
    std::vector<std::pair<Vec<3, double>, int>> spec = {{Vec<3, double>{{0.5, 0.5, 0.8}}, 1},
                                                        {Vec<3, double>{{0.5, 0.5, 0.2}}, 0},
                                                        {Vec<3, double>{{0.8, 0.3, 0.5}}, 0}};
    if (!near_first) std::swap(spec[0], spec[1]);
    const Image img = render_image(make_scene<3>(spec), o, box, 0.0);
    // The nearer particle (z = 0.8, towards the camera) hides the farther one, whatever the order.
    EXPECT_TRUE(orangeish(img.at(160, 120))) << near_first;
    EXPECT_TRUE(bluish(img.at(160 + 36, 120 + 24))) << near_first;
    EXPECT_EQ(img.at(160, 120 + 30), kBackground);
    EXPECT_EQ(img.at(160 + 36 + 20, 120 + 24), kBackground);
    // Box edges project to x = 160 +- 60, y = 120 +- 60.
    bool edge = false;
    for (int x = 98; x <= 102; ++x) edge = edge || dark_grey(img.at(x, 100));
    EXPECT_TRUE(edge);
    edge = false;
    for (int y = 178; y <= 182; ++y) edge = edge || dark_grey(img.at(200, y));
    EXPECT_TRUE(edge);
  }
}

TEST(Renderer, ThreeDimensionalPerspectiveProjection) {
  RenderOptions o = bare(320, 240);
  o.camera = Camera{{0.5, 0.5, 3}, {0.5, 0.5, 0.5}, {0, 1, 0}, 40, false, 0};
  o.particle_radius = 0.05;
  o.box_outline = false;
  const auto p = make_scene<3>({{Vec<3, double>{{0.7, 0.5, 0.5}}, 0}, {Vec<3, double>{{0.5, 0.5, 0.5}}, 1}});
  const Image img = render_image(p, o, RenderBox{{0, 0, 0}, {1, 1, 1}}, 0.0);
  // Pinhole model: x = cx + f * X / Z with f = (H/2) / tan(fov/2), Z = 2.5.
  const double f = 120 / std::tan(20 * M_PI / 180);
  const int x = static_cast<int>(std::lround(160 + f * 0.2 / 2.5));
  const double rp = f * 0.05 / 2.5;
  EXPECT_TRUE(bluish(img.at(x, 120)));
  EXPECT_TRUE(bluish(img.at(x + static_cast<int>(0.6 * rp), 120)));
  EXPECT_EQ(img.at(x + static_cast<int>(std::ceil(1.4 * rp)), 120), kBackground);
  EXPECT_TRUE(orangeish(img.at(160, 120)));
  EXPECT_EQ(img.at(160, 120 + static_cast<int>(std::ceil(1.4 * rp))), kBackground);
}

TEST(Renderer, DefaultThreeDimensionalCameraFramesTheBox) {
  RenderOptions o = bare(320, 240);
  const auto p = make_scene<3>({{Vec<3, double>{{0.5, 0.5, 0.5}}, 0}});
  o.particle_radius = 0.05;
  const Image img = render_image(p, o, RenderBox{{0, 0, 0}, {1, 1, 1}}, 0.0);
  int x0 = img.width, x1 = -1, y0 = img.height, y1 = -1, blue = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (dark_grey(img.at(x, y))) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
      blue += bluish(img.at(x, y));
    }
  // All of the box is in the picture and fills a good part of it.
  EXPECT_GT(x0, 0);
  EXPECT_LT(x1, img.width - 1);
  EXPECT_GT(y0, 0);
  EXPECT_LT(y1, img.height - 1);
  EXPECT_GT(y1 - y0, img.height / 2);
  EXPECT_GT(blue, 20);
}

TEST(Renderer, SpeedColourMapAndExplicitRange) {
  auto p = make_scene<2>({{Vec<2, double>{{0.25, 0.5}}, 0}, {Vec<2, double>{{0.75, 0.5}}, 0}});
  p.v[1] = Vec<2, double>{{2.0, 0.0}};
  RenderOptions o = bare(300, 300);
  o.color_by = ColorBy::Speed;
  o.particle_radius = 0.05;
  o.box_outline = false;
  const RenderBox box{{0, 0, 0}, {1, 1, 0}};
  // Square box in a square image: centre (150, 150), the box spans 96% of the height.
  const double s = 0.96 * 300;
  auto px = [&](double w) { return static_cast<int>(std::lround(150 + (w - 0.5) * s)); };
  const Image img = render_image(p, o, box, 0.0);
  EXPECT_TRUE(bluish(img.at(px(0.25), 150)));                             // slowest end of the map
  EXPECT_TRUE(img.at(px(0.75), 150)[0] > img.at(px(0.75), 150)[2] + 60);  // fastest: red
  o.range_min = 0.0;
  o.range_max = 10.0;  // now 2 m/s is low in the range
  EXPECT_TRUE(bluish(render_image(p, o, box, 0.0).at(px(0.75), 150)));
}

TEST(Renderer, ColourMapEndsAndPalette) {
  EXPECT_TRUE(bluish(colormap(0.0)));
  EXPECT_TRUE(colormap(1.0)[0] > 150 && colormap(1.0)[2] < 80);
  EXPECT_EQ(colormap(-3.0), colormap(0.0));
  EXPECT_EQ(colormap(7.0), colormap(1.0));
  EXPECT_NE(phase_colour(0), phase_colour(1));
  EXPECT_EQ(phase_colour(0), phase_colour(8));
  EXPECT_EQ(parse_color_by("pressure"), ColorBy::Pressure);
  EXPECT_THROW(parse_color_by("temperature"), InputError);
}

TEST(Renderer, LabelsAppearOnlyWhenAsked) {
  const auto p = make_scene<2>({{Vec<2, double>{{0.5, 0.5}}, 0}});
  RenderOptions o;  // default 1280x720 with every label
  const RenderBox box{{0, 0, 0}, {1, 1, 0}};
  const Image with = render_image(p, o, box, 1.25);
  auto ink_in = [](const Image& img, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += dark_grey(img.at(x, y));
    return n;
  };
  EXPECT_GT(ink_in(with, 0, 0, 200, 40), 50);      // "t = 1.250 s"
  EXPECT_GT(ink_in(with, 0, 660, 300, 720), 50);   // scale bar and its label
  EXPECT_GT(ink_in(with, 1050, 0, 1280, 40), 20);  // legend
  o.time_label = o.scale_bar = o.legend = false;
  const Image without = render_image(p, o, box, 1.25);
  EXPECT_EQ(ink_in(without, 0, 0, 200, 40), 0);
  EXPECT_EQ(ink_in(without, 0, 690, 300, 720), 0);
}

TEST(Renderer, PngIsDecodableDeterministicAndAtomic) {
  test::TempDir dir("render");
  const auto p = make_scene<3>({{Vec<3, double>{{0.2, 0.3, 0.4}}, 0}, {Vec<3, double>{{0.6, 0.5, 0.5}}, 1}});
  const RenderBox box{{0, 0, 0}, {1, 1, 1}};
  test::spit(dir / "f.png", "old");
  render_png(p, RenderOptions{}, box, 0.5, dir / "f.png");
  const std::string bytes = test::slurp(dir / "f.png");
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const Image back = read_png(dir / "f.png");
  EXPECT_EQ(back.width, 1280);
  EXPECT_EQ(back.height, 720);
  EXPECT_EQ(back.rgb, render_image(p, RenderOptions{}, box, 0.5).rgb);
  render_png(p, RenderOptions{}, box, 0.5, dir / "g.png");
  EXPECT_EQ(test::slurp(dir / "g.png"), bytes);
  EXPECT_EQ(dir.listing(), (std::vector<std::string>{"f.png", "g.png"}));
  EXPECT_THROW(read_png(dir / "missing.png"), InputError);
}

TEST(Renderer, BadOptionsAreInputErrors) {
  const auto p = make_scene<3>({{Vec<3, double>{{0.5, 0.5, 0.5}}, 0}});
  RenderOptions o = bare(64, 48);
  o.camera = Camera{{1, 1, 1}, {1, 1, 1}, {0, 1, 0}, 35, false, 0};
  EXPECT_THROW(render_image(p, o, RenderBox{}, 0.0), InputError);
  o.camera = Camera{{0, 0, 5}, {0, 0, 0}, {0, 0, 1}, 35, false, 0};  // up along the view
  EXPECT_THROW(render_image(p, o, RenderBox{}, 0.0), InputError);
  o.camera = Camera{{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 180, false, 0};
  EXPECT_THROW(render_image(p, o, RenderBox{}, 0.0), InputError);
  o.camera.reset();
  o.width = 0;
  EXPECT_THROW(render_image(p, o, RenderBox{}, 0.0), InputError);
}

TEST(Renderer, SameImageForAnyThreadCount) {
  std::vector<std::pair<Vec<3, double>, int>> spec;
  for (int i = 0; i < 400; ++i)
    spec.push_back(
        {Vec<3, double>{{0.05 + 0.002 * i, 0.5 + 0.3 * std::sin(i * 0.1), 0.3 + 0.001 * i}}, i % 3});
  const auto p = make_scene<3>(spec);
  RenderOptions o = bare(320, 240);
  o.particle_radius = 0.04;
  Image one, two;
  {
    ScopedThreads t(1);
    one = render_image(p, o, RenderBox{}, 0.0);
  }
  {
    ScopedThreads t(2);
    two = render_image(p, o, RenderBox{}, 0.0);
  }
  EXPECT_EQ(one.rgb, two.rgb);
}

TEST(Image, IncompressibleImageRoundTripsThroughPng) {
  // Noise compresses worse than the first buffer guess, so the encoder's second pass is exercised.
  test::TempDir dir("png_noise");
  Image img(64, 48);
  std::uint32_t state = 12345;
  for (auto& b : img.rgb) {
    state = state * 1664525u + 1013904223u;
    b = static_cast<std::uint8_t>(state >> 24);
  }
  write_png(img, dir / "n.png");
  const Image back = read_png(dir / "n.png");
  EXPECT_EQ(back.width, 64);
  EXPECT_EQ(back.height, 48);
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_GT(std::filesystem::file_size(dir / "n.png"), img.rgb.size() / 2 + 4096);
}

TEST(BitmapFont, GlyphsAndText) {
  // '.' is the 2x2 block at the bottom left-centre.
  int dots = 0;
  for (int r = 0; r < kGlyphHeight; ++r)
    for (int c = 0; c < kGlyphWidth; ++c) dots += glyph_pixel('.', c, r);
  EXPECT_EQ(dots, 4);
  EXPECT_TRUE(glyph_pixel('.', 1, 6));
  EXPECT_FALSE(glyph_pixel(' ', 2, 3));
  EXPECT_TRUE(glyph_pixel('1', 2, 0));
  EXPECT_TRUE(glyph_pixel('=', 0, 2) && glyph_pixel('=', 0, 4) && !glyph_pixel('=', 0, 3));
  for (int r = 0; r < kGlyphHeight; ++r)
    for (int c = 0; c < kGlyphWidth; ++c) EXPECT_EQ(glyph_pixel('M', c, r), glyph_pixel('m', c, r));
  EXPECT_EQ(text_width("ab", 3), (2 * kGlyphAdvance - 1) * 3);
  Image img(40, 20, {255, 255, 255});
  draw_text(img, 1, 1, ". .", {0, 0, 0}, 2);
  int ink = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) ink += img.rgb[i] == 0;
  EXPECT_EQ(ink, 2 * 4 * 4);
}

TEST(Video, MissingFfmpegIsReportedNotFatal) {
  test::TempDir dir("video");
  const auto r = make_mp4(dir.path(), "frame_%05d.png", 30, dir / "out.mp4", "cellsph-no-such-ffmpeg");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("not found on PATH"), std::string::npos) << r.message;
  EXPECT_TRUE(dir.listing().empty());
  EXPECT_TRUE(find_on_path("sh").has_value());
}

TEST(Video, EncodesFramesWhenFfmpegIsInstalled) {
  if (!find_on_path("ffmpeg"))
    GTEST_SKIP() << "ffmpeg is not installed here; the missing case is tested above";
  test::TempDir dir("video_enc");
  const auto p = make_scene<2>({{Vec<2, double>{{0.5, 0.5}}, 0}});
  RenderOptions o = bare(161, 91);  // odd sizes must be padded for yuv420p
  for (int f = 0; f < 3; ++f)
    render_png(p, o, RenderBox{}, f * 0.1, dir / ("frame_0000" + std::to_string(f) + ".png"));
  const auto r = make_mp4(dir.path(), "frame_%05d.png", 10, dir / "out.mp4");
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_GT(std::filesystem::file_size(dir / "out.mp4"), 100u);
  EXPECT_EQ(test::slurp(dir / "out.mp4").substr(4, 4), "ftyp");  // an ISO media file
  EXPECT_EQ(dir.listing(),
            (std::vector<std::string>{"frame_00000.png", "frame_00001.png", "frame_00002.png", "out.mp4"}));
}

}  // namespace
}  // namespace cellsph
