#include "integrators/common/spectral_media.hpp"

#include <algorithm>
#include <cmath>

#include "integrators/common/spectral_shading.hpp"
#include "spectral/rgb_to_spectrum.hpp"

namespace pathlab {
namespace {

// -log(1 - u): an exponential variate of rate 1 (as medium.cpp).
float exponential(Sampler& rng) { return -std::log1p(-rng.next1d()); }

bool is_grey(const Rgb& c) { return c.x == c.y && c.y == c.z; }

// An extinction: flat at a grey's value (RgbUnboundedSpectrum of a grey is exactly that: the
// table's closed form gives sigmoid(0) = 1/2, times 2m), else the unbounded spectrum.
Spectrum4 extinction_spectrum(const Rgb& c, const SampledWavelengths& wl) {
    if (is_grey(c)) return Spectrum4(c.x > 0 ? c.x : 0.0f);
    return unbounded_spectrum(c, wl);
}

// An albedo: flat at a grey's value (the closed form's exact value, without its rounding), else
// the reflectance spectrum.
Spectrum4 albedo_spectrum(const Rgb& a, const SampledWavelengths& wl) {
    if (is_grey(a)) return Spectrum4(std::clamp(a.x, 0.0f, 1.0f));
    return reflectance_spectrum(a, wl);
}

// The albedo of a homogeneous medium (it stores sigma_s = albedo sigma_t).
Rgb homogeneous_albedo(const HomogeneousMedium& h) {
    Rgb a;
    for (int c = 0; c < 3; ++c) a[c] = h.sigma_t[c] > 0 ? h.sigma_s[c] / h.sigma_t[c] : 0.0f;
    return a;
}

// beta *= f / q, r *= p / q with q the largest p_k (medium.cpp's weigh, per lane).
void weigh(Spectrum4& beta, Spectrum4& r, const Spectrum4& f, const Spectrum4& p) {
    const float q = p.max_value();
    if (!(q > 0)) {
        beta = Spectrum4(0.0f);
        return;
    }
    beta *= f / Spectrum4(q);  // true divisions: a grey medium's p / q is exactly 1
    r *= p / Spectrum4(q);
}

// A medium whose extinction is the same everywhere, and that extinction at wl.
bool constant_extinction(const Medium& m, const SampledWavelengths& wl, Spectrum4& sigma_t) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        sigma_t = extinction_spectrum(h->sigma_t, wl);
        return true;
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    if (!g.sigma_t.is_constant()) return false;
    sigma_t = extinction_spectrum(g.sigma_t.constant, wl) * g.scale;
    return true;
}

// The pieces of o + t d in [0, tmax] with their majorants, and the factor by which the
// iterator's majorants must be multiplied (see the header).
MajorantIterator majorants(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, float factor, const SampledWavelengths& wl,
                           float& grid_factor) {
    grid_factor = 1;
    Spectrum4 sigma_t;
    if (constant_extinction(m, wl, sigma_t)) return MajorantIterator::single(0, tmax, sigma_t.max_value() * factor);
    const auto& g = std::get<HeterogeneousMedium>(m);
    grid_factor = spectral_majorant_factor(m) * factor;
    const Vec3f ou(g.sigma_t.to_unit.point(Vec3d(o))), du(g.sigma_t.to_unit.vector(Vec3d(d)));
    return MajorantIterator(*g.majorants, ou, du, 0, tmax);
}

// The extinction at p (ratio tracking needs no albedo).
Spectrum4 extinction_at(const Medium& m, const Vec3f& p, const SampledWavelengths& wl) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) return extinction_spectrum(h->sigma_t, wl);
    const auto& g = std::get<HeterogeneousMedium>(m);
    return extinction_spectrum(g.sigma_t.eval(p), wl) * g.scale;
}

float compute_unbounded_spectrum_bound() {
    // The unbounded spectrum looks the table up at a colour of largest channel exactly 1/2; a
    // grey gives sigmoid(0) = 1/2.
    const float largest = std::max(0.5f, RgbToSpectrumTable::srgb().max_node_value_around(0.5f));
    return std::min(2.0f, 2 * largest * (1 + 1e-5f));
}

}  // namespace

float unbounded_spectrum_bound() {
    static const float bound = compute_unbounded_spectrum_bound();
    return bound;
}

float spectral_majorant_factor(const Medium& m) {
    const auto* g = std::get_if<HeterogeneousMedium>(&m);
    if (!g || g->sigma_t.is_constant() || g->sigma_t.grid->channels == 1) return 1;
    return unbounded_spectrum_bound();
}

SpectralMediumCoefficients spectral_medium_coefficients(const Medium& m, const Vec3f& p, const SampledWavelengths& wl) {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        const Spectrum4 sigma_t = extinction_spectrum(h->sigma_t, wl);
        return {sigma_t, albedo_spectrum(homogeneous_albedo(*h), wl) * sigma_t};
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    const Spectrum4 sigma_t = extinction_spectrum(g.sigma_t.eval(p), wl) * g.scale;
    return {sigma_t, albedo_spectrum(g.albedo.eval(p), wl) * sigma_t};
}

Spectrum4 homogeneous_transmittance(const Spectrum4& sigma_t, float distance) {
    Spectrum4 T;
    for (int i = 0; i < kSpectrumLanes; ++i) T[i] = sigma_t[i] > 0 ? std::exp(-sigma_t[i] * distance) : 1.0f;
    return T;
}

FreeFlight sample_free_flight_spectral(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, Spectrum4& beta,
                                       Spectrum4& r, const SampledWavelengths& wl, float majorant_factor) {
    Spectrum4 sigma_t;
    const bool constant = constant_extinction(m, wl, sigma_t);
    if (constant && (majorant_factor == 1 || !std::isfinite(tmax))) {
        // Exact sampling with the hero's extinction.
        const float s = sigma_t[0];
        const float t = s > 0 ? exponential(rng) / s : kInf;
        if (t < tmax) {
            const Spectrum4 T = homogeneous_transmittance(sigma_t, t);
            weigh(beta, r, spectral_medium_coefficients(m, o + d * t, wl).sigma_s * T, sigma_t * T);
            return {true, t};
        }
        const Spectrum4 T = homogeneous_transmittance(sigma_t, tmax);
        weigh(beta, r, T, T);
        return {false, tmax};
    }
    // Delta tracking against piecewise constant scalar majorants bounding every lane.
    float grid_factor;
    MajorantIterator pieces = majorants(m, o, d, tmax, majorant_factor, wl, grid_factor);
    MajorantSegment seg;
    float tau = exponential(rng);
    while (pieces.next(seg)) {
        const float sigma_maj = seg.sigma_maj * grid_factor;
        if (!(sigma_maj > 0)) continue;
        float t = seg.t0;
        for (;;) {
            const float dt = tau / sigma_maj;
            if (t + dt >= seg.t1) {
                tau -= (seg.t1 - t) * sigma_maj;
                break;
            }
            t += dt;
            const SpectralMediumCoefficients c = spectral_medium_coefficients(m, o + d * t, wl);
            if (rng.next1d() * sigma_maj < c.sigma_t[0]) {
                weigh(beta, r, c.sigma_s, c.sigma_t);
                return {true, t};
            }
            const Spectrum4 sigma_n = max(Spectrum4(0.0f), Spectrum4(sigma_maj) - c.sigma_t);
            weigh(beta, r, sigma_n, sigma_n);
            tau = exponential(rng);
        }
    }
    return {false, tmax};
}

Spectrum4 estimate_transmittance_spectral(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng,
                                          const SampledWavelengths& wl, float majorant_factor) {
    Spectrum4 sigma_t;
    if (constant_extinction(m, wl, sigma_t) && (majorant_factor == 1 || !std::isfinite(tmax)))
        return homogeneous_transmittance(sigma_t, tmax);
    // Ratio tracking.
    float grid_factor;
    MajorantIterator pieces = majorants(m, o, d, tmax, majorant_factor, wl, grid_factor);
    MajorantSegment seg;
    Spectrum4 T(1.0f);
    while (pieces.next(seg)) {
        const float sigma_maj = seg.sigma_maj * grid_factor;
        if (!(sigma_maj > 0)) continue;
        for (float t = seg.t0;;) {
            t += exponential(rng) / sigma_maj;
            if (t >= seg.t1) break;
            const Spectrum4 sigma_t_here = extinction_at(m, o + d * t, wl);
            T *= max(Spectrum4(0.0f), Spectrum4(1.0f) - sigma_t_here / sigma_maj);
            // Russian roulette on a small transmittance: unbiased, and thick media end early.
            if (const float q = T.max_value(); q < 0.1f) {
                if (rng.next1d() >= q) return Spectrum4(0.0f);
                T /= q;
            }
        }
    }
    return T;
}

}  // namespace pathlab
