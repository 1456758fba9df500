// A linear RGB float image, row-major with the top row first.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

class Image {
public:
    Image() = default;
    Image(int width, int height, Rgb fill = Rgb(0.0f))
        : width_(width), height_(height), pixels_(size_t(width) * size_t(height), fill) {}
    // Takes `pixels` (width * height of them, top row first) without copying them.
    Image(int width, int height, std::vector<Rgb>&& pixels) : width_(width), height_(height), pixels_(std::move(pixels)) {}

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return pixels_.size(); }
    Rgb& at(int x, int y) { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
    const Rgb& at(int x, int y) const { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
    Rgb& operator[](size_t i) { return pixels_[i]; }
    const Rgb& operator[](size_t i) const { return pixels_[i]; }
    const float* data() const { return &pixels_.data()->x; }
    float* data() { return &pixels_.data()->x; }

private:
    int width_ = 0, height_ = 0;
    std::vector<Rgb> pixels_;
};
static_assert(sizeof(Rgb) == 3 * sizeof(float), "Image::data() relies on packed Rgb");

// An 8-bit RGB image (PNG in and out), row-major with the top row first.
struct Image8 {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;  // 3 bytes per pixel
    uint8_t at(int x, int y, int c) const { return rgb[(size_t(y) * size_t(width) + size_t(x)) * 3 + size_t(c)]; }
};

// Display encodings of a linear value v (already scaled by exposure) to 8 bits.
uint8_t encode_srgb8(float v);             // clamp to [0,1], sRGB transfer curve, round
uint8_t encode_gamma8(float v, float gamma);  // clamp to [0,1], pure power 1/gamma, round
float decode_gamma8(uint8_t v, float gamma);  // (v/255)^gamma

// Tone-maps a linear image for display: multiply by 2^exposure, then the sRGB curve.
Image8 to_srgb8(const Image& img, float exposure_stops);
// The inverse of encode_srgb8 on its 256 codes: decode_srgb8(encode_srgb8(v)) re-encodes to the same code.
float decode_srgb8(uint8_t v);
// A PNG's 8-bit sRGB values as linear RGB.
Image from_srgb8(const Image8& img);

// A rectangle of pixels, from the top-left corner.
struct PixelRect {
    int x = 0, y = 0, width = 0, height = 0;
};
// The pixels of `rect`, which must lie inside the image (std::invalid_argument otherwise).
Image crop(const Image& img, const PixelRect& rect);

}  // namespace pathlab
