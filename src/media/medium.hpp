// Participating media: the closed set of medium types, and the two things a volumetric path
// tracer asks of a medium along a ray segment: where the path scatters next (free-flight
// sampling) and how much light gets through (transmittance). docs/volumes.md derives both.
//
// Free-flight sampling, per RGB channel, with a hero channel h and spectral MIS (Miller,
// Georgiev and Jarosz 2019): the path is sampled with channel h's coefficients, h uniform among
// the three, and its contribution f_c / p_h is replaced by f_c / mean_k p_k, the one-sample
// balance heuristic over the three channels' sampling techniques. The integrator carries
// beta_c = f_c / q and r_k = p_k / q for any common normaliser q (each step divides by the
// largest p_k, so r <= 1), and a contribution is beta * L / mean(r). Both functions below
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
#include "media/homogeneous.hpp"
#include "samplers/sampler.hpp"

namespace pathlab {

using Medium = std::variant<HomogeneousMedium, HeterogeneousMedium>;

inline const PhaseFunction& medium_phase(const Medium& m) {
    return std::visit([](const auto& x) -> const PhaseFunction& { return x.phase; }, m);
}

struct MediumCoefficients {
    Rgb sigma_t, sigma_s;
};
MediumCoefficients medium_coefficients(const Medium& m, const Vec3f& p);

// Where free-flight sampling ended: a real collision (scattering) at distance t, or no
// collision before tmax.
struct FreeFlight {
    bool scattered = false;
    float t = 0;
};

// Samples the first scattering along o + t d (d a unit vector) for t in [0, tmax) with hero
// channel `hero`, multiplying beta and r as above; the random numbers come from `rng`.
// majorant_factor > 1 inflates the majorant (null collisions in homogeneous media too; the
// tests use it, renders do not).
FreeFlight sample_free_flight(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int hero, Sampler& rng, Rgb& beta,
                              Rgb& r, float majorant_factor = 1);

// An unbiased estimate of the transmittance along o + t d, t in [0, tmax] (closed form where
// the extinction is constant, unless majorant_factor > 1 asks for ratio tracking).
Rgb estimate_transmittance(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, Sampler& rng, float majorant_factor = 1);

// exp(-sigma_t d) per channel, with exp(-0 x inf) = 1.
Rgb homogeneous_transmittance(const Rgb& sigma_t, float distance);

// The density of the free-flight distance t in a homogeneous medium for hero channel h (its
// sampling pdf): sigma_t,h exp(-sigma_t,h t); the probability of passing tmax is exp(-sigma_t,h tmax).
float free_flight_pdf(const HomogeneousMedium& m, float t, int hero);

}  // namespace pathlab
