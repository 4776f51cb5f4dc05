#pragma once
// A small 5x7 bitmap font for the labels of rendered frames (time, scale bar, legend), so pictures need
// no font library. Digits, lower-case letters, 'P' and . , = - + / : ( ) [ ] % _ ? and space; other
// upper-case letters are drawn with their lower-case glyph, anything else as '?'.
#include <string_view>

#include "cellsph/render/image.hpp"

namespace cellsph {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;  // one column of spacing

// Whether glyph `c` has its pixel (col, row) set; row 0 is the top.
bool glyph_pixel(char c, int col, int row);

// Pixel width and height of `text` at integer `scale`.
int text_width(std::string_view text, int scale);
inline int text_height(int scale) {
  return kGlyphHeight * scale;
}

// Draws `text` with its top-left corner at (x, y), each font pixel a scale x scale square.
void draw_text(Image& image, int x, int y, std::string_view text, Rgb8 colour, int scale);

}  // namespace cellsph
