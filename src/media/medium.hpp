// Participating media: the closed set of medium types, and the two things a volumetric path
// tracer asks of a medium along a ray segment: where the path scatters next (free-flight
// sampling) and how much light gets through (transmittance). docs/volumes.md derives both.
//
// Free-flight sampling, per RGB channel (or spectral lane), with a hero channel h and spectral MIS (Miller,
// Georgiev and Jarosz 2019): the path is sampled with channel h's coefficients, h uniform among
// the three, and its contribution f_c / p_h is replaced by f_c / mean_k p_k, the one-sample
// balance heuristic over the three channels' sampling techniques. The integrator carries
// beta_c = f_c / q and r_k = p_k / q for any common normaliser q (each step divides by the
// largest p_k, so r <= 1), and a contribution is beta * L / mean(r). free_flight.hpp's two functions
// multiply beta and r by the step's factors:
//  - homogeneous media sample the distance exactly: t ~ sigma_t,h exp(-sigma_t,h t);
//      scatter at t:  f_c = sigma_s,c exp(-sigma_t,c t),  p_k = sigma_t,k exp(-sigma_t,k t)
//      pass (t >= tmax): f_c = exp(-sigma_t,c tmax),  p_k = exp(-sigma_t,k tmax)
//  - grid media use delta tracking against the majorant grid's sigma_maj (one majorant for all
//    channels, so the exponentials cancel): tentative collisions at rate sigma_maj, each real
//    with probability sigma_t,h / sigma_maj, null otherwise;
//      real:  f_c = sigma_s,c,  p_k = sigma_t,k;   null:  f_c = p_c = sigma_maj - sigma_t,c
// Grey media leave r at exactly 1 and make beta the usual albedo product.
//
// Transmittance (next-event estimation): homogeneous media in closed form exp(-sigma_t d);
// grid media by ratio tracking, T_c = prod (1 - sigma_t,c(x_i) / sigma_maj) over tentative
// collisions x_i at rate sigma_maj, an unbiased estimate in [0, 1] for every channel, with
// Russian roulette once T is small.
#pragma once

#include <variant>

#include "media/heterogeneous.hpp"
#include "media/free_flight.hpp"
#include "media/homogeneous.hpp"
#include "samplers/sampler.hpp"

namespace pathlab {

using Medium = std::variant<HomogeneousMedium, HeterogeneousMedium>;

inline const PhaseFunction& medium_phase(const Medium& m) {
    return std::visit([](const auto& x) -> const PhaseFunction& { return x.phase; }, m);
}

using MediumCoefficients = MediumCoefficientsOf<Rgb>;
MediumCoefficients medium_coefficients(const Medium& m, const Vec3f& p);

// A medium seen in RGB (free_flight.hpp's view): its coefficients per channel.
struct MediumRgb {
    using Colour = Rgb;
    const Medium& m;
    bool constant_extinction(Rgb& sigma_t) const;
    Rgb extinction(const Vec3f& p) const;
    MediumCoefficients coefficients(const Vec3f& p) const { return medium_coefficients(m, p); }
    MajorantIterator majorants(const Vec3f& o, const Vec3f& d, float tmax, float factor, float& scale) const;
};

// free_flight.hpp's sampling and transmittance in RGB, hero channel `hero`.
inline FreeFlight sample_free_flight(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int hero, Sampler& rng, Rgb& beta,
                                     Rgb& r, float majorant_factor = 1) {
    return sample_free_flight(MediumRgb{m}, o, d, tmax, hero, rng, beta, r, majorant_factor);
}
inline Rgb estimate_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, float majorant_factor = 1) {
    return estimate_transmittance(MediumRgb{m}, o, d, tmax, rng, majorant_factor);
}

// True when the medium attenuates light somewhere (a vacuum, sigma_t = 0 everywhere, changes nothing).
bool has_extinction(const Medium& medium);

// The density of the free-flight distance t in a homogeneous medium for hero channel h (its
// sampling pdf): sigma_t,h exp(-sigma_t,h t); the probability of passing tmax is exp(-sigma_t,h tmax).
float free_flight_pdf(const HomogeneousMedium& m, float t, int hero);

// The distance-sampling part of the densities in the bidirectional methods' MIS weights (bdpt,
// docs/volumes.md): a deterministic function of the path, so that every strategy that can make
// a path gives its edges the same densities, and exact for grey media of constant extinction.
// A vertex in a medium reached along an edge has the density sigma(x) T(edge) per unit volume
// (times the direction's density over d^2); a surface behind the edge, T(edge) per unit area.
//   mis_extinction      the channels' mean extinction at p
//   mis_transmittance   exp(-optical depth of mis_extinction along o + t d, t in [0, tmax]):
//                       exact where the extinction is constant (0 for an infinite ray through
//                       a medium), else the midpoint rule over the majorant grid's cells
float mis_extinction(const Medium& m, const Vec3f& p);
float mis_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax);
// The same for the least extinction of the channels (the clearest channel's transmittance):
// how much light a connection can carry at most, before its transmittance is estimated.
float clearest_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax);

// estimate_transmittance(view, ...) and, in `mis`, mis_transmittance(medium, o, d, tmax), both
// bit for bit, in one walk over the majorant cells in grid media (a connection of the
// bidirectional methods needs both; the midpoint rule reads the cells ratio tracking visits).
// `view` is `medium` seen at the path's wavelengths. When ratio tracking's roulette ends the walk
// (T = 0), `mis` is what the cells before gave: nothing uses it then.
template <class View>
typename View::Colour estimate_transmittance_with_mis(const Medium& medium, const View& view, const Vec3f& o, const Vec3f& d, float tmax,
                                                      Sampler& rng, float majorant_factor, float& mis) {
    using Colour = typename View::Colour;
    Colour sigma_t;
    if (view.constant_extinction(sigma_t)) {
        mis = mis_transmittance(medium, o, d, tmax);
        return estimate_transmittance(view, o, d, tmax, rng, majorant_factor);
    }
    float depth = 0;
    const Colour T = ratio_tracking(view, o, d, tmax, rng, majorant_factor, [](float, const Colour&) {}, [&](const MajorantSegment& seg) {
        if (!(seg.sigma_maj > 0)) return;  // nothing there (as mis_transmittance)
        depth += std::isfinite(seg.t1) ? mis_extinction(medium, o + d * (0.5f * (seg.t0 + seg.t1))) * (seg.t1 - seg.t0) : kInf;
    });
    mis = std::exp(-depth);
    return T;
}

}  // namespace pathlab
