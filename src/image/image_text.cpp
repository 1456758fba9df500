#include "image/image_text.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace pathlab {

int text_width(const std::string& text) {
    std::string copy = text;
    return stb_easy_font_width(copy.data());
}

void draw_text(Image& image, int x, int y, const std::string& text, Rgb colour) {
    // stb_easy_font emits quads: 4 vertices of (x, y, z floats, 4 colour bytes) each.
    struct Vertex {
        float x, y, z;
        unsigned char rgba[4];
    };
    std::vector<Vertex> quads(4 * (text.size() * 16 + 16));
    std::string copy = text;
    const int n = stb_easy_font_print(float(x), float(y), copy.data(), nullptr, quads.data(), int(quads.size() * sizeof(Vertex)));
    for (int q = 0; q < n; ++q) {
        const Vertex* v = &quads[size_t(q) * 4];
        const int x0 = std::max(0, int(std::lround(std::min(v[0].x, v[2].x)))), x1 = std::min(image.width(), int(std::lround(std::max(v[0].x, v[2].x))));
        const int y0 = std::max(0, int(std::lround(std::min(v[0].y, v[2].y)))), y1 = std::min(image.height(), int(std::lround(std::max(v[0].y, v[2].y))));
        for (int py = y0; py < y1; ++py)
            for (int px = x0; px < x1; ++px) image.at(px, py) = colour;
    }
}

}  // namespace pathlab
