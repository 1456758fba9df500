#include "render/pixel_filter.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

PixelFilter::PixelFilter(const FilterDesc& f, int width, int height)
    : f_(f), width_(width), height_(height), plain_(f.is_box() && f.radius == 0.5), reach_(int(std::floor(f.radius + 0.5))) {}

double PixelFilter::lattice_sum(int q, double u, int size) const {
    double d = 0;
    for (int p = std::max(0, q - reach_); p <= std::min(size - 1, q + reach_); ++p) d += f_.eval(p + u - (q + 0.5));
    return d;
}

double PixelFilter::weight(int q, double x, int size) const {
    const double u = x - std::floor(x);
    const double d = lattice_sum(q, u, size);
    return d > 0 ? f_.eval(x - (q + 0.5)) / d : 0.0;
}

void PixelFilter::filter_pass(const std::vector<Vec3d>& lattice, const Vec2f& shift, std::vector<Vec3d>& out) const {
    const int w = width_, h = height_, r = reach_;
    // The 1D weights of offset o = p - q for each pixel q along an axis (borders renormalised).
    const auto axis_weights = [&](int size, double u) {
        std::vector<double> k(size_t(size) * size_t(2 * r + 1), 0.0);
        for (int q = 0; q < size; ++q) {
            const double d = lattice_sum(q, u, size);
            for (int o = -r; o <= r; ++o)
                if (q + o >= 0 && q + o < size && d > 0) k[size_t(q) * size_t(2 * r + 1) + size_t(o + r)] = f_.eval(o + u - 0.5) / d;
        }
        return k;
    };
    const std::vector<double> kx = axis_weights(w, shift.x), ky = axis_weights(h, shift.y);
    std::vector<Vec3d> rows(lattice.size(), Vec3d(0.0));
    for (int y = 0; y < h; ++y)
        for (int q = 0; q < w; ++q) {
            Vec3d s(0.0);
            for (int o = std::max(-r, -q); o <= std::min(r, w - 1 - q); ++o)
                s += lattice[size_t(y) * size_t(w) + size_t(q + o)] * kx[size_t(q) * size_t(2 * r + 1) + size_t(o + r)];
            rows[size_t(y) * size_t(w) + size_t(q)] = s;
        }
    out.assign(lattice.size(), Vec3d(0.0));
    for (int q = 0; q < h; ++q)
        for (int o = std::max(-r, -q); o <= std::min(r, h - 1 - q); ++o) {
            const double k = ky[size_t(q) * size_t(2 * r + 1) + size_t(o + r)];
            if (k == 0) continue;
            for (int x = 0; x < w; ++x) out[size_t(q) * size_t(w) + size_t(x)] += rows[size_t(q + o) * size_t(w) + size_t(x)] * k;
        }
}

void PixelFilter::splat(const Vec2f& r, const Vec3d& value, std::vector<Vec3d>& out) const {
    const int bx = std::min(int(r.x), width_ - 1), by = std::min(int(r.y), height_ - 1);
    double wx[17], wy[17];  // reach <= 8
    for (int o = -reach_; o <= reach_; ++o) {
        wx[o + reach_] = bx + o >= 0 && bx + o < width_ ? weight(bx + o, r.x, width_) : 0.0;
        wy[o + reach_] = by + o >= 0 && by + o < height_ ? weight(by + o, r.y, height_) : 0.0;
    }
    for (int oy = -reach_; oy <= reach_; ++oy) {
        if (wy[oy + reach_] == 0) continue;
        for (int ox = -reach_; ox <= reach_; ++ox)
            if (wx[ox + reach_] != 0)
                out[size_t(by + oy) * size_t(width_) + size_t(bx + ox)] += value * (wx[ox + reach_] * wy[oy + reach_]);
    }
}

}  // namespace pathlab
