#include "integrators/cache/micro_buffer.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

MicroBuffer::MicroBuffer(int n) : n_(std::max(1, n)) {
    const size_t count = size_t(n_) * size_t(n_);
    local_.resize(count);
    world_.resize(count);
    pixels_.assign(count, Pixel{});
    for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i)
            local_[size_t(j) * size_t(n_) + size_t(i)] = square_to_direction(2 * (float(i) + 0.5f) / float(n_) - 1, 2 * (float(j) + 0.5f) / float(n_) - 1);
}

Vec3f MicroBuffer::square_to_direction(float u, float v) {
    // Shirley-Chiu: the square's concentric squares onto the disk's concentric circles.
    float r, phi;
    if (u == 0 && v == 0) return Vec3f(0, 0, 1);
    if (std::abs(u) > std::abs(v)) r = u, phi = (kPi / 4) * (v / u);
    else r = v, phi = kPi / 2 - (kPi / 4) * (u / v);
    const float dx = r * std::cos(phi), dy = r * std::sin(phi);
    return Vec3f(dx, dy, std::sqrt(std::max(0.0f, 1 - dx * dx - dy * dy)));  // Malley: up onto the hemisphere
}

namespace {

// atan(t) for |t| <= 1 within 1e-5 radians (a minimax polynomial in t^2; the map's inverse needs
// no more, and libm's atan2 was a tenth of a gather's time).
float atan_unit(float t) {
    const float t2 = t * t;
    return t * (0.99997726f + t2 * (-0.33262347f + t2 * (0.19354346f + t2 * (-0.11643287f + t2 * (0.05265332f - t2 * 0.01172120f)))));
}

}  // namespace

void MicroBuffer::direction_to_square(const Vec3f& local, float& u, float& v) {
    // The disk point (x, y) = (r cos phi, r sin phi) back to the square: in the wedge around +x
    // (|y| <= x) u = r, v = r phi / (pi/4) with phi = atan(y / x); the other wedges alike.
    const float x = local.x, y = local.y;
    const float r = std::sqrt(x * x + y * y);
    if (r == 0) {
        u = v = 0;
        return;
    }
    constexpr float k = 4 / kPi;
    if (std::abs(x) >= std::abs(y)) {
        const float a = r * k * atan_unit(y / x);
        if (x > 0) u = r, v = a;
        else u = -r, v = -a;
    } else {
        const float a = r * k * atan_unit(x / y);
        if (y > 0) v = r, u = a;
        else v = -r, u = -a;
    }
}

void MicroBuffer::clear(const Vec3f& x, const Frame& frame) {
    x_ = x, frame_ = frame;
    world_ready_ = false;
    std::fill(pixels_.begin(), pixels_.end(), Pixel{});
}

void MicroBuffer::cover(size_t pixel, float f, const Rgb& L, float near, float far) {
    Pixel& p = pixels_[pixel];
    if (!(f > 0) || !(p.open > 0)) return;
    if (p.layer_coverage > 0 && near > p.layer_depth) {
        // Beyond the current layer: it hides min(1, its coverage) of what is left.
        p.sum += p.layer_sum * p.open;
        p.layer_sum = Rgb(0.0f);
        if (p.layer_coverage >= 1) {
            p.open = 0;
            return;
        }
        p.open *= 1 - p.layer_coverage;
        p.layer_coverage = 0;
    }
    p.layer_depth = p.layer_coverage > 0 ? std::max(p.layer_depth, far) : far;
    p.layer_coverage += f;
    p.layer_sum += L * f;
}

void MicroBuffer::add_square(const Vec3f& d, float omega, const Rgb& L, float near, float far) {
    const Vec3f local = frame_.to_local(d);
    if (!(local.z > 0) || !(omega > 0)) return;
    float u, v;
    direction_to_square(local, u, v);
    // The square's area in the map (4 for the whole hemisphere, pi of projected solid angle).
    const float half = std::sqrt(std::min(omega, 2 * kPi) * local.z / kPi);
    // Kept inside the map: an element above the horizon keeps all its area (the map squeezes
    // shapes near the rim radially, so a square there would poke out of it).
    if (half < 1) u = std::clamp(u, -1 + half, 1 - half), v = std::clamp(v, -1 + half, 1 - half);
    const float scale = 0.5f * float(n_);
    const float x0 = (u - half + 1) * scale, x1 = (u + half + 1) * scale;
    const float y0 = (v - half + 1) * scale, y1 = (v + half + 1) * scale;
    const int i0 = std::max(0, int(std::floor(x0))), i1 = std::min(n_ - 1, int(std::floor(x1)));
    const int j0 = std::max(0, int(std::floor(y0))), j1 = std::min(n_ - 1, int(std::floor(y1)));
    for (int j = j0; j <= j1; ++j) {
        const float oy = std::min(float(j + 1), y1) - std::max(float(j), y0);
        if (!(oy > 0)) continue;
        for (int i = i0; i <= i1; ++i) {
            const float ox = std::min(float(i + 1), x1) - std::max(float(i), x0);
            if (ox > 0) cover(size_t(j) * size_t(n_) + size_t(i), ox * oy, L, near, far);
        }
    }
}

void MicroBuffer::add_disk(const Vec3f& p, const Vec3f& nd, float r, const Rgb& L, float near, float far) {
    if (!world_ready_) {
        for (size_t k = 0; k < local_.size(); ++k) world_[k] = frame_.to_world(local_[k]);
        world_ready_ = true;
    }
    const Vec3f to = p - x_;
    const float h = dot(to, nd), r2 = r * r;
    for (size_t k = 0; k < world_.size(); ++k) {
        if (!(pixels_[k].open > 0)) continue;
        const float denom = dot(world_[k], nd);
        if (denom == 0) continue;
        const float t = h / denom;
        if (!(t > 0)) continue;
        const Vec3f q = world_[k] * t - to;
        if (dot(q, q) <= r2) cover(k, 1.0f, L, near, far);
    }
}

Rgb MicroBuffer::irradiance() const {
    Vec3d sum(0.0);
    for (const Pixel& p : pixels_) sum += Vec3d(p.sum + p.layer_sum * p.open);
    return Rgb(sum * (double(kPi) / double(pixels_.size())));
}

}  // namespace pathlab
