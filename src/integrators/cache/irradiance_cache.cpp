#include "integrators/cache/irradiance_cache.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

void IrradianceCache::reset(float a, float cell, bool gradients) {
    a_ = a, cell_ = cell, gradients_ = gradients;
    records_.clear();
    cells_.clear();
}

uint64_t IrradianceCache::key(int x, int y, int z) const {
    // 21 bits per axis (cubes far out wrap around: a lookup there only sees more records to test).
    const auto b = [](int v) { return uint64_t(uint32_t(v) & 0x1fffffu); };
    return b(x) | (b(y) << 21) | (b(z) << 42);
}

void IrradianceCache::insert(uint32_t index) {
    const IrradianceRecord& r = records_[index];
    const float reach = a_ * r.R;
    const auto lo = [&](float v) { return int(std::floor((v - reach) / cell_)); };
    const auto hi = [&](float v) { return int(std::floor((v + reach) / cell_)); };
    for (int z = lo(r.p.z); z <= hi(r.p.z); ++z)
        for (int y = lo(r.p.y); y <= hi(r.p.y); ++y)
            for (int x = lo(r.p.x); x <= hi(r.p.x); ++x) cells_[key(x, y, z)].push_back(index);
}

void IrradianceCache::add(const IrradianceRecord& r) {
    records_.push_back(r);
    insert(uint32_t(records_.size() - 1));
}

template <typename F> void IrradianceCache::for_each_near(const Vec3f& x, F&& f) const {
    const auto it = cells_.find(key(int(std::floor(x.x / cell_)), int(std::floor(x.y / cell_)), int(std::floor(x.z / cell_))));
    if (it == cells_.end()) return;
    for (const uint32_t i : it->second) f(records_[i]);
}

namespace {

// Ward's error e_i of using record r at (x, n), or a value >= a when it may not be used.
float ward_error(const IrradianceRecord& r, const Vec3f& x, const Vec3f& n, float a) {
    const Vec3f d = x - r.p;
    if (dot(d, (n + r.n) * 0.5f) < -0.01f * r.R) return a;  // the record is in front of x
    return length(d) / r.R + std::sqrt(std::max(0.0f, 1 - dot(n, r.n)));
}

}  // namespace

bool IrradianceCache::covered(const Vec3f& x, const Vec3f& n) const {
    bool any = false;
    for_each_near(x, [&](const IrradianceRecord& r) { any |= ward_error(r, x, n, a_) < a_; });
    return any;
}

bool IrradianceCache::interpolate(const Vec3f& x, const Vec3f& n, Rgb& E) const {
    double wsum = 0;
    Vec3d sum(0.0);
    for_each_near(x, [&](const IrradianceRecord& r) {
        const float e = ward_error(r, x, n, a_);
        if (!(e < a_)) return;
        const double w = 1.0 / std::max(double(e), 1e-6) - 1.0 / a_;
        Rgb Ei = r.E;
        if (gradients_) {
            const Vec3f rot = cross(r.n, n), d = x - r.p;
            for (int c = 0; c < 3; ++c) Ei[c] += dot(rot, r.grad_r[c]) + dot(d, r.grad_t[c]);
        }
        sum += Vec3d(max(Ei, Rgb(0.0f))) * w;
        wsum += w;
    });
    if (!(wsum > 0)) return false;
    E = Rgb(sum / wsum);
    return true;
}

void IrradianceCache::clamp_to_neighbours() {
    for (size_t i = 0; i < records_.size(); ++i) {
        IrradianceRecord& ri = records_[i];
        for_each_near(ri.p, [&](const IrradianceRecord& rj) {
            if (&rj == &ri || !(ward_error(rj, ri.p, ri.n, a_) < a_)) return;
            ri.R = std::min(ri.R, rj.R + length(ri.p - rj.p));
        });
    }
    cells_.clear();
    for (uint32_t i = 0; i < records_.size(); ++i) insert(i);
}

}  // namespace pathlab
