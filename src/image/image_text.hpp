// Labels drawn into an image: stb_easy_font's 5x7 pixel glyphs (cells about 6 pixels wide and 12
// high, the text's top at y), as solid rectangles, for figures whose cells need names (bdpt's
// strategy montage).
#pragma once

#include <string>

#include "image/image.hpp"

namespace pathlab {

inline constexpr int kTextHeight = 12;  // a line's height in pixels

// Width in pixels of `text` drawn by draw_text.
int text_width(const std::string& text);
// Draws `text` with its top left corner at (x, y), clipped to the image.
void draw_text(Image& image, int x, int y, const std::string& text, Rgb colour);

}  // namespace pathlab
