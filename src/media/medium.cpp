#include "media/medium.hpp"

#include <cmath>

namespace pathlab {
namespace {

// -log(1 - u): an exponential variate of rate 1 (u in [0, 1), so never infinite).
float exponential(Sampler& rng) { return -std::log1p(-rng.next1d()); }

// beta *= f / q, r *= p / q with q the largest p_k.
void weigh(Rgb& beta, Rgb& r, const Rgb& f, const Rgb& p) {
    const float q = max_component(p);
    if (!(q > 0)) {  // an event of probability 0 (a null collision exactly at sigma_maj)
        beta = Rgb(0.0f);
        return;
    }
    beta *= f / Rgb(q);  // true divisions: a grey medium's p / q is exactly 1
    r *= p / Rgb(q);
}

// A medium whose extinction is the same everywhere: homogeneous, or heterogeneous with a
// constant sigma_t (its albedo may still vary).
bool constant_extinction(const Medium& m, Rgb& sigma_t) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        sigma_t = h->sigma_t;
        return true;
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    if (!g.sigma_t.is_constant()) return false;
    sigma_t = g.sigma_t.constant * g.scale;
    return true;
}

// The pieces of o + t d in [0, tmax] with their majorants.
MajorantIterator majorants(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, float factor) {
    Rgb sigma_t;
    if (constant_extinction(m, sigma_t)) return MajorantIterator::single(0, tmax, max_component(sigma_t) * factor);
    const auto& g = std::get<HeterogeneousMedium>(m);
    // The grid's unit space: an affine map keeps the ray parameter t.
    const Vec3f ou(g.sigma_t.to_unit.point(Vec3d(o))), du(g.sigma_t.to_unit.vector(Vec3d(d)));
    return MajorantIterator(*g.majorants, ou, du, 0, tmax);
}

}  // namespace

MediumCoefficients medium_coefficients(const Medium& m, const Vec3f& p) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) return {h->sigma_t, h->sigma_s};
    const auto& g = std::get<HeterogeneousMedium>(m);
    const Rgb sigma_t = g.extinction(p);
    return {sigma_t, g.albedo.eval(p) * sigma_t};
}

Rgb homogeneous_transmittance(const Rgb& sigma_t, float distance) {
    Rgb T;
    for (int c = 0; c < 3; ++c) T[c] = sigma_t[c] > 0 ? std::exp(-sigma_t[c] * distance) : 1.0f;
    return T;
}

float free_flight_pdf(const HomogeneousMedium& m, float t, int hero) {
    const float s = m.sigma_t[hero];
    return s * std::exp(-s * t);
}

FreeFlight sample_free_flight(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int hero, Sampler& rng, Rgb& beta,
                              Rgb& r, float majorant_factor) {
    Rgb sigma_t;
    const bool constant = constant_extinction(m, sigma_t);
    if (constant && (majorant_factor == 1 || !std::isfinite(tmax))) {
        // Exact sampling with the hero channel's extinction.
        const float s = sigma_t[hero];
        const float t = s > 0 ? exponential(rng) / s : kInf;
        if (t < tmax) {
            const Rgb T = homogeneous_transmittance(sigma_t, t);
            weigh(beta, r, medium_coefficients(m, o + d * t).sigma_s * T, sigma_t * T);
            return {true, t};
        }
        const Rgb T = homogeneous_transmittance(sigma_t, tmax);
        weigh(beta, r, T, T);
        return {false, tmax};
    }
    // Delta tracking against piecewise constant majorants. One exponential variate tau is
    // spent across the pieces (the majorant's optical depth up to the next tentative collision).
    MajorantIterator pieces = majorants(m, o, d, tmax, majorant_factor);
    MajorantSegment seg;
    float tau = exponential(rng);
    while (pieces.next(seg)) {
        if (!(seg.sigma_maj > 0)) continue;
        float t = seg.t0;
        for (;;) {
            const float dt = tau / seg.sigma_maj;
            if (t + dt >= seg.t1) {
                tau -= (seg.t1 - t) * seg.sigma_maj;
                break;
            }
            t += dt;
            const MediumCoefficients c = medium_coefficients(m, o + d * t);
            if (rng.next1d() * seg.sigma_maj < c.sigma_t[hero]) {
                weigh(beta, r, c.sigma_s, c.sigma_t);
                return {true, t};
            }
            const Rgb sigma_n = max(Rgb(0.0f), Rgb(seg.sigma_maj) - c.sigma_t);
            weigh(beta, r, sigma_n, sigma_n);
            tau = exponential(rng);
        }
    }
    return {false, tmax};
}

Rgb estimate_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, float majorant_factor) {
    Rgb sigma_t;
    if (constant_extinction(m, sigma_t) && (majorant_factor == 1 || !std::isfinite(tmax))) return homogeneous_transmittance(sigma_t, tmax);
    // Ratio tracking.
    MajorantIterator pieces = majorants(m, o, d, tmax, majorant_factor);
    MajorantSegment seg;
    Rgb T(1.0f);
    while (pieces.next(seg)) {
        if (!(seg.sigma_maj > 0)) continue;
        for (float t = seg.t0;;) {
            t += exponential(rng) / seg.sigma_maj;
            if (t >= seg.t1) break;
            const Rgb sigma_t_here = medium_coefficients(m, o + d * t).sigma_t;
            T *= max(Rgb(0.0f), Rgb(1.0f) - sigma_t_here / seg.sigma_maj);
            // Russian roulette on a small transmittance: unbiased, and thick media end early.
            if (const float q = max_component(T); q < 0.1f) {
                if (rng.next1d() >= q) return Rgb(0.0f);
                T /= q;
            }
        }
    }
    return T;
}

}  // namespace pathlab
