#include "textures/bitmap.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <fmt/format.h>

#include "image/image_io.hpp"
#include "textures/srgb.hpp"

namespace pathlab {
namespace {

Rgb lerp(const Rgb& a, const Rgb& b, float t) { return a + (b - a) * t; }

// floor(x) as an int where |x| < 2^30 (every lookup but those at absurd or non-finite uv),
// without a call to floor().
bool floor_int(double x, int& i) {
    if (!(x > -1073741824.0 && x < 1073741824.0)) return false;
    i = int(x);  // truncates towards zero
    if (double(i) > x) --i;
    return true;
}

}  // namespace

BitmapTexture::BitmapTexture(int width, int height, std::vector<Rgb> texels, FilterType filter, WrapMode wrap, UvTransform to_uv,
                             bool colour, std::string name)
    : width_(width), height_(height), texels_(std::move(texels)), filter_(filter), wrap_(wrap), to_uv_(to_uv), colour_(colour),
      name_(std::move(name)) {
    if (width_ <= 0 || height_ <= 0 || texels_.size() != size_t(width_) * size_t(height_))
        throw std::invalid_argument(fmt::format("a bitmap texture of {}x{} texels needs {} of them, not {}", width_, height_,
                                                size_t(std::max(width_, 0)) * size_t(std::max(height_, 0)), texels_.size()));
    min_ = max_ = texels_[0];
    for (const Rgb& t : texels_) {
        min_ = min(min_, t), max_ = max(max_, t);
        monochrome_ = monochrome_ && t.x == t.y && t.y == t.z;
    }
}

int BitmapTexture::wrap_index(int i, int n) const {
    if (unsigned(i) < unsigned(n)) return i;  // inside: every mode leaves it
    switch (wrap_) {
        case WrapMode::Clamp: return i < 0 ? 0 : n - 1;
        case WrapMode::Repeat: {
            const int m = i % n;
            return m < 0 ? m + n : m;
        }
        case WrapMode::Mirror:
        default: {
            int m = i % (2 * n);  // 2n < 2^30: images have at most 2^28 texels
            if (m < 0) m += 2 * n;
            return m < n ? m : 2 * n - 1 - m;
        }
    }
}

int BitmapTexture::wrap(double i, int n) const {
    int k;
    if (floor_int(i, k)) return wrap_index(k, n);
    const double nd = n;
    double m;
    switch (wrap_) {
        case WrapMode::Clamp: m = i; break;
        case WrapMode::Repeat: m = i - nd * std::floor(i / nd); break;
        case WrapMode::Mirror:
        default:
            m = i - 2 * nd * std::floor(i / (2 * nd));
            if (m >= nd) m = 2 * nd - 1 - m;
            break;
    }
    // (Rounding can leave m just outside [0, n) for enormous i.)
    return int(std::clamp(m, 0.0, nd - 1));
}

BitmapTexture::Cell BitmapTexture::bilinear_cell(const Vec2f& uv) const {
    const Vec2f t = to_uv_.apply(uv);
    double x = double(t.x) * width_ - 0.5, y = double(t.y) * height_ - 0.5;
    int i, j;
    if (floor_int(x, i) && floor_int(y, j))  // the common case
        return {wrap_index(i, width_), wrap_index(i + 1, width_), wrap_index(j, height_), wrap_index(j + 1, height_),
                float(x - i), float(y - j)};
    if (!std::isfinite(x)) x = 0;
    if (!std::isfinite(y)) y = 0;
    const double x0 = std::floor(x), y0 = std::floor(y);
    return {wrap(x0, width_), wrap(x0 + 1, width_), wrap(y0, height_), wrap(y0 + 1, height_), float(x - x0), float(y - y0)};
}

Rgb BitmapTexture::eval(const Vec2f& uv) const {
    if (filter_ == FilterType::Nearest) return texels_[footprint(uv).index[0]];
    const Cell c = bilinear_cell(uv);
    const Rgb top = lerp(texels_[index(c.x0, c.y0)], texels_[index(c.x1, c.y0)], c.fx);
    const Rgb bottom = lerp(texels_[index(c.x0, c.y1)], texels_[index(c.x1, c.y1)], c.fx);
    return lerp(top, bottom, c.fy);
}

float BitmapTexture::eval_1(const Vec2f& uv) const {
    const Rgb v = eval(uv);
    return monochrome_ ? v.x : luminance(v);
}

Vec2f BitmapTexture::eval_1_grad(const Vec2f& uv) const {
    if (filter_ == FilterType::Nearest) return {0.0f, 0.0f};
    const Cell c = bilinear_cell(uv);
    const float f00 = scalar(index(c.x0, c.y0)), f10 = scalar(index(c.x1, c.y0));
    const float f01 = scalar(index(c.x0, c.y1)), f11 = scalar(index(c.x1, c.y1));
    // d/dx and d/dy in texels, then per unit of u' and v', then of u and v.
    const float gx = (1 - c.fy) * (f10 - f00) + c.fy * (f11 - f01);
    const float gy = (1 - c.fx) * (f01 - f00) + c.fx * (f11 - f10);
    return to_uv_.pull_back({gx * float(width_), gy * float(height_)});
}

TexelFootprint BitmapTexture::footprint(const Vec2f& uv) const {
    TexelFootprint f;
    if (filter_ == FilterType::Nearest) {
        const Vec2f t = to_uv_.apply(uv);
        double x = double(t.x) * width_, y = double(t.y) * height_;
        int i, j;
        if (floor_int(x, i) && floor_int(y, j)) {
            f.index[0] = uint32_t(index(wrap_index(i, width_), wrap_index(j, height_)));
        } else {
            x = std::isfinite(x) ? std::floor(x) : 0, y = std::isfinite(y) ? std::floor(y) : 0;
            f.index[0] = uint32_t(index(wrap(x, width_), wrap(y, height_)));
        }
        f.weight[0] = 1;
        f.count = 1;
        return f;
    }
    const Cell c = bilinear_cell(uv);
    f.index = {uint32_t(index(c.x0, c.y0)), uint32_t(index(c.x1, c.y0)), uint32_t(index(c.x0, c.y1)), uint32_t(index(c.x1, c.y1))};
    f.weight = {(1 - c.fx) * (1 - c.fy), c.fx * (1 - c.fy), (1 - c.fx) * c.fy, c.fx * c.fy};
    f.count = 4;
    return f;
}

BitmapTexture load_bitmap_texture(const std::string& path, bool raw, FilterType filter, WrapMode wrap, UvTransform to_uv) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    std::vector<Rgb> texels;
    int w = 0, h = 0;
    bool colour = true;
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp") {
        const Image8 img = ext == ".png" ? read_png8(path) : ext == ".bmp" ? read_bmp8(path) : read_jpeg8(path);
        const std::array<float, 256>& srgb = srgb8_to_linear_table();
        w = img.width, h = img.height;
        texels.resize(size_t(w) * size_t(h));
        for (size_t i = 0; i < texels.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                const uint8_t v = img.rgb[i * 3 + size_t(k)];
                texels[i][k] = raw ? float(v) / 255.0f : srgb[v];
            }
        colour = !raw;
    } else if (ext == ".exr" || ext == ".hdr" || ext == ".pfm") {
        Image img = read_image(path);
        w = img.width(), h = img.height();
        texels.resize(img.pixel_count());
        for (size_t i = 0; i < texels.size(); ++i) {
            texels[i] = img[i];
            if (!is_finite(texels[i]))
                throw ImageIoError(fmt::format("{}: texel ({}, {}) is not finite", path, i % size_t(w), i / size_t(w)));
        }
    } else {
        throw ImageIoError(fmt::format("{}: unsupported texture image '{}' (supported: .png, .jpg, .jpeg, .bmp, .exr, .hdr, .pfm)", path,
                                       ext.empty() ? "(no extension)" : ext));
    }
    return BitmapTexture(w, h, std::move(texels), filter, wrap, to_uv, colour, path);
}

}  // namespace pathlab
