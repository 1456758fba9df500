#include "image/image.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

uint8_t encode_srgb8(float v) {
    if (!(v > 0.0f)) return 0;  // also maps NaN to black
    v = std::min(v, 1.0f);
    const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return static_cast<uint8_t>(std::lround(s * 255.0f));
}

uint8_t encode_gamma8(float v, float gamma) {
    if (!(v > 0.0f)) return 0;
    v = std::min(v, 1.0f);
    return static_cast<uint8_t>(std::lround(255.0f * std::pow(v, 1.0f / gamma)));
}

float decode_gamma8(uint8_t v, float gamma) { return std::pow(float(v) / 255.0f, gamma); }

Image8 to_srgb8(const Image& img, float exposure_stops) {
    Image8 out{img.width(), img.height(), std::vector<uint8_t>(img.pixel_count() * 3)};
    const float scale = std::exp2(exposure_stops);
    for (size_t i = 0; i < img.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) out.rgb[i * 3 + size_t(c)] = encode_srgb8(img[i][c] * scale);
    return out;
}

}  // namespace pathlab
