// Phase functions: how a medium scatters light at a point. A closed set (std::variant, as the
// BSDFs are), each with its scene-file plugin.
//
// Conventions (as the BSDFs'): both directions are unit vectors in world space pointing away
// from the scattering point, `wi` back towards where the path came from, `wo` the other one.
// Light travelling along -wi is scattered into wo; the scattering angle theta is the angle
// between -wi and wo (theta = 0: straight on). eval(wi, wo) is the phase function p, a density
// per unit solid angle of wo that integrates to 1, so a sample's weight p / pdf is exactly 1.
//
//   isotropic  p = 1 / (4 pi)
//   hg         Henyey-Greenstein, p = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2)),
//              g the mean cosine of theta: g > 0 forward, g < 0 backward scattering
//
// XML (Mitsuba 3): <phase type="isotropic"/>, <phase type="hg"> <float name="g" value="0.7"/>.
#pragma once

#include <cmath>
#include <optional>
#include <variant>

#include "core/frame.hpp"
#include "core/properties.hpp"
#include "core/sampling.hpp"

namespace pathlab {

struct PhaseSample {
    Vec3f wo;
    float p = 0;     // the phase function's value
    float pdfW = 0;  // the density of wo (equal to p for both phase functions here)
};

struct IsotropicPhase {
    float eval(const Vec3f&, const Vec3f&) const { return uniform_sphere_pdf(); }
    float pdf(const Vec3f&, const Vec3f&) const { return uniform_sphere_pdf(); }
    PhaseSample sample(const Vec3f&, const Vec2f& u) const {
        return {square_to_uniform_sphere(u), uniform_sphere_pdf(), uniform_sphere_pdf()};
    }
};

struct HgPhase {
    float g = 0;  // in (-1, 1)

    // The density of the scattering angle's cosine mu, per unit solid angle.
    float density(float mu) const {
        const float denom = 1 + g * g - 2 * g * mu;
        return (1 - g * g) / (4 * kPi * denom * std::sqrt(std::max(denom, 1e-12f)));
    }
    float eval(const Vec3f& wi, const Vec3f& wo) const { return density(-dot(wi, wo)); }
    float pdf(const Vec3f& wi, const Vec3f& wo) const { return density(-dot(wi, wo)); }
    // Inverts the cumulative distribution of mu: mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g)
    // (uniform for |g| < 1e-3, where that form loses its digits); phi uniform about -wi.
    PhaseSample sample(const Vec3f& wi, const Vec2f& u) const {
        float mu;
        if (std::abs(g) < 1e-3f) {
            mu = 1 - 2 * u.x;
        } else {
            const float s = (1 - g * g) / (1 - g + 2 * g * u.x);
            mu = (1 + g * g - s * s) / (2 * g);
        }
        mu = std::clamp(mu, -1.0f, 1.0f);
        const float sin_theta = std::sqrt(std::max(0.0f, 1 - mu * mu));
        const float phi = 2 * kPi * u.y;
        const Vec3f wo = normalize(Frame(-wi).to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu}));
        const float p = eval(wi, wo);
        return {wo, p, p};
    }
};

using PhaseFunction = std::variant<IsotropicPhase, HgPhase>;

inline float phase_eval(const PhaseFunction& f, const Vec3f& wi, const Vec3f& wo) {
    return std::visit([&](const auto& m) { return m.eval(wi, wo); }, f);
}
inline float phase_pdf(const PhaseFunction& f, const Vec3f& wi, const Vec3f& wo) {
    return std::visit([&](const auto& m) { return m.pdf(wi, wo); }, f);
}
inline PhaseSample phase_sample(const PhaseFunction& f, const Vec3f& wi, const Vec2f& u) {
    return std::visit([&](const auto& m) { return m.sample(wi, u); }, f);
}

inline const PluginInfo& isotropic_phase_plugin() {
    static const PluginInfo info{"phase", "isotropic", "scatters equally in all directions (a medium's default)", {}};
    return info;
}
inline const PluginInfo& hg_phase_plugin() {
    static const PluginInfo info{"phase", "hg", "Henyey-Greenstein",
                                 {{"g", ParamType::Float, "0.8", "mean cosine of the scattering angle, in (-1, 1): > 0 forward, < 0 backward"}}};
    return info;
}
inline HgPhase read_hg_phase(Properties& p) {
    const float g = p.get_float("g");
    if (!(g > -1 && g < 1)) p.fail("g", "g must lie strictly between -1 and 1");
    return HgPhase{g};
}

}  // namespace pathlab
