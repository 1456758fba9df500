#include "image/image.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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

float decode_srgb8(uint8_t v) {
    const float s = float(v) / 255.0f;
    return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

Image from_srgb8(const Image8& img) {
    Image out(img.width, img.height);
    for (size_t i = 0; i < out.pixel_count(); ++i)
        out[i] = Rgb(decode_srgb8(img.rgb[i * 3]), decode_srgb8(img.rgb[i * 3 + 1]), decode_srgb8(img.rgb[i * 3 + 2]));
    return out;
}

Image crop(const Image& img, const PixelRect& r) {
    if (r.x < 0 || r.y < 0 || r.width <= 0 || r.height <= 0 || r.x + r.width > img.width() || r.y + r.height > img.height())
        throw std::invalid_argument("the crop " + std::to_string(r.x) + "," + std::to_string(r.y) + "," + std::to_string(r.width) + "," +
                                    std::to_string(r.height) + " is not inside the " + std::to_string(img.width()) + "x" +
                                    std::to_string(img.height()) + " image");
    Image out(r.width, r.height);
    for (int y = 0; y < r.height; ++y)
        for (int x = 0; x < r.width; ++x) out.at(x, y) = img.at(r.x + x, r.y + y);
    return out;
}

}  // namespace pathlab
