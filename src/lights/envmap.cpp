#include "lights/envmap.hpp"

#include <cmath>

#include <fmt/format.h>

#include "image/image_io.hpp"

namespace pathlab {
namespace {

// The largest sin(theta) over the rows' band theta in [y pi / H, (y + 1) pi / H].
float row_max_sin_theta(int y, int height) {
    const double t0 = double(y) / height, t1 = double(y + 1) / height;
    if (t0 <= 0.5 && t1 >= 0.5) return 1.0f;
    return float(std::max(std::sin(t0 * M_PI), std::sin(t1 * M_PI)));
}

// The bilinear lookup at image coordinates (s, t) = (u W - 1/2, v (H - 1)) of values fetch(x, y):
// texel-centred in u, wrapping around; corner-aligned in v (row y at v = y / (H - 1)), as
// Mitsuba 3's envmap.cpp (eval_spectrum) looks it up. Shared by the lookup (colours) and the
// sampling bound (luminances).
template <typename Fetch>
auto bilinear_at(float s, float t, int width, int height, Fetch&& fetch) {
    const float fs = std::floor(s);
    const int y0 = std::min(int(t), std::max(height - 2, 0)), y1 = std::min(y0 + 1, height - 1);
    const float wx = s - fs, wy = t - float(y0);
    // u in [0, 1): fs in [-1, W - 1]; other u wrap by a modulo.
    int x0 = int(fs);
    if (x0 < 0 || x0 >= width) x0 = ((x0 % width) + width) % width;
    const int x1 = x0 + 1 == width ? 0 : x0 + 1;
    return (fetch(x0, y0) * (1 - wx) + fetch(x1, y0) * wx) * (1 - wy) + (fetch(x0, y1) * (1 - wx) + fetch(x1, y1) * wx) * wy;
}

}  // namespace

EnvMap::EnvMap(int width, int height, std::vector<Rgb> texels, const Frame& to_world)
    : width_(width), height_(height), texels_(std::move(texels)), frame_(to_world) {
    std::vector<float> lum(texels_.size());
    for (size_t i = 0; i < texels_.size(); ++i) lum[i] = luminance(texels_[i]);
    // The lookup's luminance at image coordinates (s, t) (t within [0, H - 1]).
    const auto bilinear = [&](float s, float t) {
        return bilinear_at(s, t, width_, height_, [&](int x, int y) { return lum[size_t(y) * size_t(width_) + size_t(x)]; });
    };
    std::vector<float> f(texels_.size());
    double mean = 0;
    for (int y = 0; y < height_; ++y) {
        const float sin_max = row_max_sin_theta(y, height_);
        // The texel's solid angle, for the mean radiance.
        const double omega = 2 * M_PI / width_ * (std::cos(M_PI * y / height_) - std::cos(M_PI * (y + 1) / height_));
        // The cell's rows: from t0 to t1, with the image rows between (at most one: t1 - t0 < 1).
        const float t0 = float(double(y) * (height_ - 1) / height_), t1 = float(double(y + 1) * (height_ - 1) / height_);
        float ts[3] = {t0, t1, t0};
        const int between = int(std::floor(t0)) + 1;
        if (float(between) < t1) ts[2] = float(between);
        for (int x = 0; x < width_; ++x) {
            // The bilinear function's maximum over the cell is at a corner of one of its patches:
            // columns x - 1/2, x, x + 1/2 (the cell's edges and the texel's centre) by the rows above.
            float m = 0;
            for (const float t : ts)
                for (const float dx : {-0.5f, 0.0f, 0.5f}) m = std::max(m, bilinear(float(x) + dx, t));
            f[size_t(y) * size_t(width_) + size_t(x)] = m * sin_max;
            mean += double(pathlab::mean(texel(x, y))) * omega;
        }
    }
    distribution_ = Distribution2D(f, width_, height_);
    mean_radiance_ = float(mean / (4 * M_PI));
}

Rgb EnvMap::lookup(Vec2f uv) const {
    return bilinear_at(uv.x * float(width_) - 0.5f, std::clamp(uv.y, 0.0f, 1.0f) * float(height_ - 1), width_, height_,
                       [&](int x, int y) { return texel(x, y); });
}

Vec3f EnvMap::uv_to_direction(Vec2f uv) {
    const float theta = uv.y * kPi, phi = uv.x * (2 * kPi);
    const float sin_theta = std::sin(theta);
    return {std::sin(phi) * sin_theta, std::cos(theta), -std::cos(phi) * sin_theta};
}

Vec2f EnvMap::direction_to_uv(const Vec3f& d) {
    float u = std::atan2(d.x, -d.z) * (0.5f * kInvPi);
    if (u < 0) u += 1;
    if (u >= 1) u = 0;
    // v = 1 (straight down, or rounded to it) belongs to the last row, as the sampler's v < 1 does.
    return {u, std::min(std::acos(std::clamp(d.y, -1.0f, 1.0f)) * kInvPi, 0x1.fffffep-1f)};
}

std::pair<int, int> EnvMap::texel_of(const Vec3f& w) const {
    const Vec2f uv = direction_to_uv(frame_.to_local(w));
    return {std::min(int(uv.x * float(width_)), width_ - 1), std::min(int(uv.y * float(height_)), height_ - 1)};
}

std::optional<EnvMap::Sample> EnvMap::sample(Vec2f u) const {
    Sample s;
    float pdf_uv;
    s.uv = distribution_.sample_continuous(u, pdf_uv, &s.x, &s.y);
    const Vec3f local = uv_to_direction(s.uv);
    const float sin_theta = std::sqrt(local.x * local.x + local.z * local.z);
    s.pdfW = uv_density_to_solid_angle(pdf_uv, sin_theta);
    if (!(s.pdfW > 0)) return std::nullopt;
    s.wi = frame_.to_world(local);
    s.Le = lookup(s.uv);
    return s;
}

float EnvMap::pdf(const Vec3f& w) const {
    const Vec3f local = frame_.to_local(normalize(w));
    const float sin_theta = std::sqrt(local.x * local.x + local.z * local.z);
    const Vec2f uv = direction_to_uv(local);
    return uv_density_to_solid_angle(distribution_.pdf(uv), sin_theta);
}

const PluginInfo& envmap_plugin() {
    static const PluginInfo info{
        "emitter", "envmap", "an environment map: radiance from every direction, from a latitude-longitude image",
        {{"filename", ParamType::String, "", "the image (.exr, .hdr or .pfm; linear RGB), relative to the scene file"},
         {"scale", ParamType::Float, "1", "multiplies the image's radiance"},
         {"to_world", ParamType::Transform, "", "orientation (a rotation); the image's top looks along +y, its centre along +z", "toWorld"}},
        "Mitsuba 3's latitude-longitude convention; importance-sampled by luminance x sin(theta), bilinear lookup "
        "(docs/lights.md). Negative texels (from some resampling filters) are read as 0; NaN or infinite ones are an error."};
    return info;
}

EnvMapLight read_envmap_light(Properties& p, const EmitterContext& ctx) {
    const std::string path = emitter_file(p, ctx, "envmap");
    const float scale = p.get_float("scale");
    if (!(scale >= 0)) p.fail("scale", "an envmap's scale must not be negative");
    const Frame frame = rotation_frame(p, "envmap");
    Image img;
    try {
        // 2^25 pixels (8192 x 4096): the texels and their distribution take about 1 GiB.
        img = read_image(path, ImageReadLimits{uint64_t(1) << 25});
    } catch (const ImageIoError& e) {
        p.fail("filename", e.what());
    }
    if (img.pixel_count() == 0) p.fail("filename", fmt::format("{}: the image has no pixels", path));
    std::vector<Rgb> texels(img.pixel_count());
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const Rgb& v = img.at(x, y);
            if (!is_finite(v)) p.fail("filename", fmt::format("{}: texel ({}, {}) is NaN or infinite", path, x, y));
            texels[size_t(y) * size_t(img.width()) + size_t(x)] = max(v, Rgb(0.0f)) * scale;
        }
    return EnvMapLight{std::make_shared<const EnvMap>(img.width(), img.height(), std::move(texels), frame)};
}

}  // namespace pathlab
