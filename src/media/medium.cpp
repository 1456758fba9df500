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

}  // namespace pathlab
