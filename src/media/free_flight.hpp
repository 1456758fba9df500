// Free-flight sampling and transmittance estimation (medium.hpp states the estimators), written
// once for any colour a path carries: RGB's 3 channels or spectral mode's 4 wavelength lanes.
// What they ask of a medium comes from a view of it at that colour (MediumRgb in medium.cpp,
// MediumAtWavelengths in spectral_medium.hpp):
//   using Colour;                                  Rgb or Spectrum4
//   bool constant_extinction(Colour& sigma_t)      the same extinction everywhere (and which)
//   Colour extinction(p)                           sigma_t at p
//   MediumCoefficientsOf<Colour> coefficients(p)   sigma_t and sigma_s at p
//   MajorantIterator majorants(o, d, tmax, factor, float& scale)
//                                                  the pieces of the ray with scalar majorants,
//                                                  each to be multiplied by `scale` to bound every
//                                                  channel (factor > 1 inflates them: the tests)
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "media/majorant_grid.hpp"
#include "samplers/sampler.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

template <class Colour>
struct MediumCoefficientsOf {
    Colour sigma_t, sigma_s;
};

// Where free-flight sampling ended: a real collision (scattering) at distance t, or no
// collision before tmax.
struct FreeFlight {
    bool scattered = false;
    float t = 0;
};

namespace free_flight_detail {

// -log(1 - u): an exponential variate of rate 1 (u in [0, 1), so never infinite).
inline float exponential(Sampler& rng) { return -std::log1p(-rng.next1d()); }

template <class Colour> inline constexpr int kChannels = 3;
template <> inline constexpr int kChannels<Spectrum4> = kSpectrumLanes;


// beta *= f / q, r *= p / q with q the largest p_k.
template <class Colour>
void weigh(Colour& beta, Colour& r, const Colour& f, const Colour& p) {
    const float q = max_component(p);
    if (!(q > 0)) {  // an event of probability 0 (a null collision exactly at sigma_maj)
        beta = Colour(0.0f);
        return;
    }
    beta *= f / Colour(q);  // true divisions: a grey medium's p / q is exactly 1
    r *= p / Colour(q);
}

}  // namespace free_flight_detail

// exp(-sigma_t d) per channel, with exp(-0 x inf) = 1.
template <class Colour>
Colour homogeneous_transmittance(const Colour& sigma_t, float distance) {
    Colour T = sigma_t;
    for (int c = 0; c < free_flight_detail::kChannels<Colour>; ++c) T[c] = sigma_t[c] > 0 ? std::exp(-sigma_t[c] * distance) : 1.0f;
    return T;
}

// Samples the first scattering along o + t d (d a unit vector) for t in [0, tmax) with hero
// channel `hero`, multiplying beta and r by the step's factors (medium.hpp); the random numbers
// come from `rng`.
template <class View>
FreeFlight sample_free_flight(const View& m, const Vec3f& o, const Vec3f& d, float tmax, int hero, Sampler& rng,
                              typename View::Colour& beta, typename View::Colour& r, float majorant_factor = 1) {
    using Colour = typename View::Colour;
    using namespace free_flight_detail;
    Colour sigma_t;
    const bool constant = m.constant_extinction(sigma_t);
    if (constant && (majorant_factor == 1 || !std::isfinite(tmax))) {
        // Exact sampling with the hero channel's extinction.
        const float s = sigma_t[hero];
        const float t = s > 0 ? exponential(rng) / s : kInf;
        if (t < tmax) {
            const Colour T = homogeneous_transmittance(sigma_t, t);
            weigh(beta, r, m.coefficients(o + d * t).sigma_s * T, sigma_t * T);
            return {true, t};
        }
        const Colour T = homogeneous_transmittance(sigma_t, tmax);
        weigh(beta, r, T, T);
        return {false, tmax};
    }
    // Delta tracking against piecewise constant majorants. One exponential variate tau is
    // spent across the pieces (the majorant's optical depth up to the next tentative collision).
    float scale;
    MajorantIterator pieces = m.majorants(o, d, tmax, majorant_factor, scale);
    MajorantSegment seg;
    float tau = exponential(rng);
    while (pieces.next(seg)) {
        const float sigma_maj = seg.sigma_maj * scale;
        if (!(sigma_maj > 0)) continue;
        float t = seg.t0;
        for (;;) {
            const float dt = tau / sigma_maj;
            if (t + dt >= seg.t1) {
                tau -= (seg.t1 - t) * sigma_maj;
                break;
            }
            t += dt;
            const MediumCoefficientsOf<Colour> c = m.coefficients(o + d * t);
            if (rng.next1d() * sigma_maj < c.sigma_t[hero]) {
                weigh(beta, r, c.sigma_s, c.sigma_t);
                return {true, t};
            }
            const Colour sigma_n = max(Colour(0.0f), Colour(sigma_maj) - c.sigma_t);
            weigh(beta, r, sigma_n, sigma_n);
            tau = exponential(rng);
        }
    }
    return {false, tmax};
}

// Ratio tracking along o + t d, t in [0, tmax]: the running estimate after every tentative
// collision goes to step(t, T); returns the estimate of T(0, tmax). A Russian roulette on a small
// transmittance (unbiased, and thick media end early) may end it, with T = 0. Each piece of
// constant majorant goes to piece(segment) before its collisions are tracked.
template <class View, class Step, class Piece>
typename View::Colour ratio_tracking(const View& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, float majorant_factor,
                                     Step&& step, Piece&& piece) {
    using Colour = typename View::Colour;
    using namespace free_flight_detail;
    float scale;
    MajorantIterator pieces = m.majorants(o, d, tmax, majorant_factor, scale);
    MajorantSegment seg;
    Colour T(1.0f);
    while (pieces.next(seg)) {
        piece(std::as_const(seg));
        const float sigma_maj = seg.sigma_maj * scale;
        if (!(sigma_maj > 0)) continue;
        for (float t = seg.t0;;) {
            t += exponential(rng) / sigma_maj;
            if (t >= seg.t1) break;
            T *= max(Colour(0.0f), Colour(1.0f) - m.extinction(o + d * t) / sigma_maj);
            if (const float q = max_component(T); q < 0.1f) {
                if (rng.next1d() >= q) {
                    T = Colour(0.0f);
                    step(t, T);
                    return T;
                }
                T /= q;
            }
            step(t, T);
        }
    }
    return T;
}
template <class View, class Step>
typename View::Colour ratio_tracking(const View& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, float majorant_factor,
                                     Step&& step) {
    return ratio_tracking(m, o, d, tmax, rng, majorant_factor, step, [](const MajorantSegment&) {});
}

// An unbiased estimate of the transmittance along o + t d, t in [0, tmax] (closed form where
// the extinction is constant, unless majorant_factor > 1 asks for ratio tracking).
template <class View>
typename View::Colour estimate_transmittance(const View& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng,
                                             float majorant_factor = 1) {
    using Colour = typename View::Colour;
    Colour sigma_t;
    if (m.constant_extinction(sigma_t) && (majorant_factor == 1 || !std::isfinite(tmax))) return homogeneous_transmittance(sigma_t, tmax);
    return ratio_tracking(m, o, d, tmax, rng, majorant_factor, [](float, const Colour&) {});
}

// The transmittance from o along o + t d for every t in [0, tmax] at once (the beam radiance
// estimate needs it at many points of one ray): exp(-sigma_t t) where the extinction is
// constant; else one ratio-tracking walk, whose running product after the tentative collisions
// before t is an unbiased estimate of T(0, t) for every t (a roulette that ends it makes the
// rest 0, one that keeps it divides by its probability: still unbiased for every prefix).
template <class Colour>
struct TransmittanceTrack {
    bool constant = false;
    Colour sigma_t{0.0f};
    std::vector<float> t;   // the tentative collisions, increasing
    std::vector<Colour> T;  // the estimate after each

    Colour at(float distance) const {
        if (constant) return homogeneous_transmittance(sigma_t, distance);
        const size_t k = size_t(std::upper_bound(t.begin(), t.end(), distance) - t.begin());
        return k == 0 ? Colour(1.0f) : T[k - 1];
    }
};

template <class View>
void track_transmittance(const View& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng,
                         TransmittanceTrack<typename View::Colour>& track) {
    track.t.clear(), track.T.clear();
    track.constant = m.constant_extinction(track.sigma_t);
    if (track.constant) return;
    ratio_tracking(m, o, d, tmax, rng, 1.0f, [&track](float t, const typename View::Colour& T) {
        track.t.push_back(t);
        track.T.push_back(T);
    });
}

}  // namespace pathlab
