#include "media/medium.hpp"

#include <cmath>

namespace pathlab {

MediumCoefficients medium_coefficients(const Medium& m, const Vec3f& p) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) return {h->sigma_t, h->sigma_s};
    const auto& g = std::get<HeterogeneousMedium>(m);
    const Rgb sigma_t = g.extinction(p);
    return {sigma_t, g.albedo.eval(p) * sigma_t};
}

// A medium whose extinction is the same everywhere: homogeneous, or heterogeneous with a
// constant sigma_t (its albedo may still vary).
bool MediumRgb::constant_extinction(Rgb& sigma_t) const {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        sigma_t = h->sigma_t;
        return true;
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    if (!g.sigma_t.is_constant()) return false;
    sigma_t = g.sigma_t.constant * g.scale;
    return true;
}

Rgb MediumRgb::extinction(const Vec3f& p) const {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) return h->sigma_t;
    return std::get<HeterogeneousMedium>(m).extinction(p);
}

// The pieces of o + t d in [0, tmax] with their majorants (the grid's bound every channel).
MajorantIterator MediumRgb::majorants(const Vec3f& o, const Vec3f& d, float tmax, float factor, float& scale) const {
    Rgb sigma_t;
    scale = 1;
    if (constant_extinction(sigma_t)) return MajorantIterator::single(0, tmax, max_component(sigma_t) * factor);
    const auto& g = std::get<HeterogeneousMedium>(m);
    scale = factor;
    // The grid's unit space: an affine map keeps the ray parameter t.
    const Vec3f ou(g.sigma_t.to_unit.point(Vec3d(o))), du(g.sigma_t.to_unit.vector(Vec3d(d)));
    return MajorantIterator(*g.majorants, ou, du, 0, tmax);
}

float free_flight_pdf(const HomogeneousMedium& m, float t, int hero) {
    const float s = m.sigma_t[hero];
    return s * std::exp(-s * t);
}

bool has_extinction(const Medium& medium) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&medium)) return max_component(h->sigma_t) > 0;
    const auto& g = std::get<HeterogeneousMedium>(medium);
    return g.scale > 0 && g.sigma_t.max_value() > 0;
}

float mis_extinction(const Medium& m, const Vec3f& p) { return mean(MediumRgb{m}.extinction(p)); }

namespace {

// exp(-optical depth of channel(sigma_t)) along o + t d, t in [0, tmax]: exact where the
// extinction is constant, else the midpoint rule over the majorant grid's cells.
template <class Channel>
float midpoint_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Channel channel) {
    const MediumRgb view{m};
    Rgb sigma_t;
    if (view.constant_extinction(sigma_t)) {
        const float s = channel(sigma_t);
        return s > 0 ? std::exp(-s * tmax) : 1.0f;
    }
    float scale, depth = 0;
    MajorantIterator pieces = view.majorants(o, d, tmax, 1, scale);
    MajorantSegment seg;
    while (pieces.next(seg)) {
        if (!(seg.sigma_maj > 0)) continue;  // nothing there
        if (!std::isfinite(seg.t1)) return 0.0f;
        depth += channel(view.extinction(o + d * (0.5f * (seg.t0 + seg.t1)))) * (seg.t1 - seg.t0);
    }
    return std::exp(-depth);
}

}  // namespace

float mis_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax) {
    return midpoint_transmittance(m, o, d, tmax, [](const Rgb& s) { return mean(s); });
}

float clearest_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax) {
    return midpoint_transmittance(m, o, d, tmax, [](const Rgb& s) { return std::min({s.x, s.y, s.z}); });
}

}  // namespace pathlab
