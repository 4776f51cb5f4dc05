#pragma once
// An 8-bit RGB image and its PNG encoding (libpng's simplified API, no display needed).
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace cellsph {

using Rgb8 = std::array<std::uint8_t, 3>;

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, top row first, 3 bytes per pixel

  Image() = default;
  Image(int w, int h, Rgb8 fill = {0, 0, 0});
  [[nodiscard]] Rgb8 at(int x, int y) const {
    const auto i = 3 * (static_cast<std::size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
  void set(int x, int y, Rgb8 c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const auto i = 3 * (static_cast<std::size_t>(y) * width + x);
    rgb[i] = c[0];
    rgb[i + 1] = c[1];
    rgb[i + 2] = c[2];
  }
  // Blends colour c over the pixel with opacity a in [0, 1].
  void blend(int x, int y, Rgb8 c, double a);
  void fill_rect(int x0, int y0, int x1, int y1, Rgb8 c, double a = 1.0);  // [x0,x1) x [y0,y1)
};

std::string encode_png(const Image& image);
// Writes atomically (temporary file, then rename).
void write_png(const Image& image, const std::filesystem::path& path);
// Decodes any PNG to 8-bit RGB. Throws InputError naming the file.
Image read_png(const std::filesystem::path& path);

// The libpng this build writes with, e.g. "1.6.39" (`cellsph doctor`).
std::string libpng_version();

}  // namespace cellsph
