#include "judge/false_colour.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "judge/image_compare.hpp"

namespace pathlab {
namespace {

// Control points of the cool-warm map (Moreland 2009) at t = -1, -0.5, 0, 0.5, 1, in sRGB;
// linear interpolation between them is close to his Msh-space interpolation.
constexpr double kCoolWarm[5][3] = {
    {59, 76, 192}, {141, 176, 254}, {221, 221, 221}, {244, 154, 124}, {180, 4, 38}};

// Viridis (van der Walt and Smith, matplotlib's default) at t = 0, 0.25, 0.5, 0.75, 1, in sRGB.
constexpr double kViridis[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};

double channel_mean(const Rgb& v) { return (double(v.x) + double(v.y) + double(v.z)) / 3.0; }

bool finite(const Rgb& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check_sizes(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height())
        throw ImageSizeMismatch(fmt::format("images differ in size: {}x{} and {}x{}", a.width(), a.height(), b.width(), b.height()));
}

}  // namespace

std::array<uint8_t, 3> diverging_colour(double t) {
    const double x = (std::clamp(std::isnan(t) ? 0.0 : t, -1.0, 1.0) + 1.0) * 2.0;  // 0..4
    const int i = std::min(3, int(x));
    const double f = x - i;
    std::array<uint8_t, 3> out{};
    for (int c = 0; c < 3; ++c)
        out[size_t(c)] = uint8_t(std::lround(kCoolWarm[i][c] + f * (kCoolWarm[i + 1][c] - kCoolWarm[i][c])));
    return out;
}

double difference_scale(const Image& a, const Image& b, double quantile) {
    check_sizes(a, b);
    std::vector<float> abs_diff;
    abs_diff.reserve(a.pixel_count());
    for (size_t i = 0; i < a.pixel_count(); ++i)
        if (finite(a[i]) && finite(b[i])) abs_diff.push_back(std::abs(luminance(a[i]) - luminance(b[i])));
    if (abs_diff.empty()) return 1.0;
    const size_t k = std::min(abs_diff.size() - 1, size_t(std::clamp(quantile, 0.0, 1.0) * double(abs_diff.size())));
    std::nth_element(abs_diff.begin(), abs_diff.begin() + long(k), abs_diff.end());
    double scale = abs_diff[k];
    if (!(scale > 0)) scale = *std::max_element(abs_diff.begin(), abs_diff.end());
    return scale > 0 ? scale : 1.0;
}

Image8 false_colour_difference(const Image& a, const Image& b, double scale) {
    check_sizes(a, b);
    if (!(scale > 0) || !std::isfinite(scale)) throw std::invalid_argument(fmt::format("difference scale must be positive, got {}", scale));
    Image8 out{a.width(), a.height(), std::vector<uint8_t>(a.pixel_count() * 3)};
    for (size_t i = 0; i < a.pixel_count(); ++i) {
        std::array<uint8_t, 3> rgb{0, 255, 0};
        if (finite(a[i]) && finite(b[i])) rgb = diverging_colour((luminance(a[i]) - luminance(b[i])) / scale);
        std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + long(i * 3));
    }
    return out;
}

Image8 diverging_colour_bar(int width, int height) {
    Image8 out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3)};
    for (int x = 0; x < width; ++x) {
        const auto rgb = diverging_colour(width > 1 ? 2.0 * x / (width - 1) - 1.0 : 0.0);
        for (int y = 0; y < height; ++y) std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + (long(y) * width + x) * 3);
    }
    return out;
}

std::array<uint8_t, 3> sequential_colour(double t) {
    const double x = std::clamp(std::isnan(t) ? 0.0 : t, 0.0, 1.0) * 4.0;  // 0..4
    const int i = std::min(3, int(x));
    const double f = x - i;
    std::array<uint8_t, 3> out{};
    for (int c = 0; c < 3; ++c) out[size_t(c)] = uint8_t(std::lround(kViridis[i][c] + f * (kViridis[i + 1][c] - kViridis[i][c])));
    return out;
}

double magnitude_scale(const Image& img, double quantile) {
    std::vector<double> v;
    v.reserve(img.pixel_count());
    for (size_t i = 0; i < img.pixel_count(); ++i)
        if (finite(img[i])) v.push_back(std::abs(channel_mean(img[i])));
    if (v.empty()) return 1.0;
    const size_t k = std::min(v.size() - 1, size_t(std::clamp(quantile, 0.0, 1.0) * double(v.size())));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    double scale = v[k];
    if (!(scale > 0)) scale = *std::max_element(v.begin(), v.end());
    return scale > 0 ? scale : 1.0;
}

Image8 false_colour_magnitude(const Image& img, double scale) {
    if (!(scale > 0) || !std::isfinite(scale)) throw std::invalid_argument(fmt::format("scale must be positive, got {}", scale));
    Image8 out{img.width(), img.height(), std::vector<uint8_t>(img.pixel_count() * 3)};
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        std::array<uint8_t, 3> rgb{255, 0, 0};
        if (finite(img[i])) rgb = sequential_colour(std::abs(channel_mean(img[i])) / scale);
        std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + long(i * 3));
    }
    return out;
}

Image8 sequential_colour_bar(int width, int height) {
    Image8 out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3)};
    for (int x = 0; x < width; ++x) {
        const auto rgb = sequential_colour(width > 1 ? double(x) / (width - 1) : 0.0);
        for (int y = 0; y < height; ++y) std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + (long(y) * width + x) * 3);
    }
    return out;
}

}  // namespace pathlab
