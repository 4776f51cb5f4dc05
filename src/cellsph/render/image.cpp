#include "cellsph/render/image.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"

namespace cellsph {

Image::Image(int w, int h, Rgb8 fill) : width(w), height(h), rgb(3 * static_cast<std::size_t>(w) * h) {
  for (std::size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = fill[0];
    rgb[i + 1] = fill[1];
    rgb[i + 2] = fill[2];
  }
}

void Image::blend(int x, int y, Rgb8 c, double a) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  const auto i = 3 * (static_cast<std::size_t>(y) * width + x);
  for (int k = 0; k < 3; ++k) {
    const double v = (1 - a) * rgb[i + k] + a * c[k];
    rgb[i + k] = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
  }
}

void Image::fill_rect(int x0, int y0, int x1, int y1, Rgb8 c, double a) {
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(width, x1); ++x) {
      if (a >= 1)
        set(x, y, c);
      else
        blend(x, y, c, a);
    }
}

std::string encode_png(const Image& image) {
  CELLSPH_CHECK(image.width > 0 && image.height > 0, "empty image " << image.width << "x" << image.height);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // Fast compression: 3x quicker here for a file a few percent larger (measured on rendered frames,
  // which are mostly flat background).
  png.flags = PNG_IMAGE_FLAG_FAST;
  // One pass into a buffer that usually fits (frames compress well); libpng reports the size it needs
  // if not, and the second pass then fits.
  std::string bytes(image.rgb.size() / 2 + 4096, '\0');
  for (int attempt = 0; attempt < 2; ++attempt) {
    png_alloc_size_t size = bytes.size();
    const auto given = size;
    if (png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), 0, nullptr)) {
      bytes.resize(size);
      png_image_free(&png);
      return bytes;
    }
    if (size <= given) break;  // a real error, not a small buffer
    bytes.resize(size);
    png.warning_or_error = 0;
  }
  const std::string message = png.message;
  png_image_free(&png);
  throw std::runtime_error("PNG encoding failed: " + message);
}

void write_png(const Image& image, const std::filesystem::path& path) {
  write_file_atomic(path, encode_png(image));
}

Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw InputError("cannot read PNG '" + path.string() + "': " + png.message);
  png.format = PNG_FORMAT_RGB;
  Image img(static_cast<int>(png.width), static_cast<int>(png.height));
  if (!png_image_finish_read(&png, nullptr, img.rgb.data(), 0, nullptr)) {
    png_image_free(&png);
    throw InputError("cannot decode PNG '" + path.string() + "': " + png.message);
  }
  return img;
}

std::string libpng_version() {
  return png_get_libpng_ver(nullptr);
}

}  // namespace cellsph
