// Microfacet normal distributions for the rough BSDFs: GGX (Trowbridge-Reitz) and Beckmann,
// isotropic or anisotropic (roughness alpha_u along the local x axis, alpha_v along y), with
// the Smith masking function of each.
//
//   GGX:      D(h) = 1 / (pi au av (hx^2/au^2 + hy^2/av^2 + hz^2)^2)
//             Lambda(w) = (sqrt(1 + a^2) - 1) / 2,  a^2 = (au^2 wx^2 + av^2 wy^2) / wz^2
//   Beckmann: D(h) = exp(-(hx^2/au^2 + hy^2/av^2) / hz^2) / (pi au av hz^4)
//             Lambda(w) = (exp(-c^2) / (c sqrt(pi)) - erfc(c)) / 2,  c = 1 / a
//
// (Walter et al. 2007, "Microfacet models for refraction through rough surfaces"; Heitz 2014,
// "Understanding the masking-shadowing function".) D is normalised so that the projected
// microfacet area is 1: integral of D(h) hz dh = 1. Masking is Smith's G1 = 1 / (1 + Lambda(w));
// shadowing-masking is its separable form G2 = G1(wi) G1(wo), as Mitsuba 3 (microfacet.h, G)
// and Mitsuba 0.6 use it, so that scenes render as their authors saw them there. (The
// height-correlated form 1 / (1 + Lambda(wi) + Lambda(wo)) of Heitz 2014, which pbrt-v4 uses,
// is larger where both directions are grazing: the roughest sphere of Mitsuba's roughplastic
// render test had a ring of failing pixels at its rim with it.)
//
// Sampling: the distribution of normals visible from wi (wi.z > 0; callers flip to the upper
// hemisphere), density D_wi(h) = G1(wi) max(0, wi.h) D(h) / wi.z for both distributions.
//   GGX: Heitz 2018, "Sampling the GGX distribution of visible normals" (closed form).
//   Beckmann: Heitz & d'Eon 2014, "Importance sampling microfacet-based BSDFs using the
//     distribution of visible normals": in the configuration stretched to roughness 1 and
//     rotated so that wi lies in the xz plane at angle theta, the visible slopes (x, y) are
//     independent, y with density exp(-y^2) / sqrt(pi) and x with density proportional to
//     (cot theta - x) exp(-x^2) for x < cot theta. Both CDFs (erf-based) are inverted by
//     safeguarded Newton iterations in double precision, so the samples follow D_wi to
//     within double rounding.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/properties.hpp"
#include "core/vec.hpp"

namespace pathlab {

enum class MicrofacetType : unsigned char { Beckmann, GGX };

struct MicrofacetDistribution {
    // The scene-file defaults are those of the plugins' parameters (microfacet_params below);
    // a test checks that these agree with them.
    MicrofacetType type = MicrofacetType::Beckmann;
    float alpha_u = 0.1f, alpha_v = 0.1f;

    // Roughness below this is clamped: D would overflow float.
    static constexpr float kMinAlpha = 1e-4f;

    MicrofacetDistribution() = default;
    MicrofacetDistribution(MicrofacetType t, float au, float av)
        : type(t), alpha_u(std::max(au, kMinAlpha)), alpha_v(std::max(av, kMinAlpha)) {}

    // Density of microfacet normals per unit solid angle (projected-area normalised).
    float D(const Vec3f& h) const {
        if (h.z <= 0) return 0.0f;
        const float x = h.x / alpha_u, y = h.y / alpha_v, z2 = h.z * h.z;
        if (type == MicrofacetType::GGX) {
            const float t = x * x + y * y + z2;
            return 1.0f / (kPi * alpha_u * alpha_v * t * t);
        }
        return std::exp(-(x * x + y * y) / z2) / (kPi * alpha_u * alpha_v * z2 * z2);
    }

    // Smith's Lambda: the masked fraction of projected microfacet area, relative.
    float lambda(const Vec3f& w) const {
        const float z2 = w.z * w.z;
        if (z2 == 0) return kInf;
        const float a2 = (alpha_u * alpha_u * w.x * w.x + alpha_v * alpha_v * w.y * w.y) / z2;  // alpha^2 tan^2
        if (type == MicrofacetType::GGX) return a2 / (2 * (std::sqrt(1 + a2) + 1));  // = (sqrt(1+a2) - 1) / 2
        if (a2 == 0) return 0.0f;
        const double c = 1.0 / std::sqrt(double(a2));
        return float(0.5 * (std::exp(-c * c) / (c * std::sqrt(M_PI)) - std::erfc(c)));
    }

    float G1(const Vec3f& w) const { return 1.0f / (1.0f + lambda(w)); }
    // Separable masking-shadowing of wi and wo (both must see the facet h: callers check).
    float G2(const Vec3f& wi, const Vec3f& wo) const { return G1(wi) * G1(wo); }

    // A microfacet normal for directions seen from wi (wi.z > 0); see the header comment.
    Vec3f sample(const Vec3f& wi, const Vec2f& u) const {
        if (type == MicrofacetType::Beckmann) return sample_beckmann(wi, u);
        // Heitz 2018: stretch wi to the configuration of roughness 1, sample the projected
        // hemisphere as seen from it (a disk, with its lower half foreshortened), unstretch.
        const Vec3f v = normalize(Vec3f(alpha_u * wi.x, alpha_v * wi.y, wi.z));
        const float len2 = v.x * v.x + v.y * v.y;
        const Vec3f t1 = len2 > 0 ? Vec3f(-v.y, v.x, 0) / std::sqrt(len2) : Vec3f(1, 0, 0);
        const Vec3f t2 = cross(v, t1);
        const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
        const float p1 = r * std::cos(phi);
        float p2 = r * std::sin(phi);
        const float s = 0.5f * (1 + v.z);
        p2 = (1 - s) * std::sqrt(std::max(0.0f, 1 - p1 * p1)) + s * p2;
        const Vec3f n = t1 * p1 + t2 * p2 + v * std::sqrt(std::max(0.0f, 1 - p1 * p1 - p2 * p2));
        return normalize(Vec3f(alpha_u * n.x, alpha_v * n.y, std::max(1e-7f, n.z)));
    }

    // Density of sample(wi, .) at the normal h, per unit solid angle of h.
    float pdf(const Vec3f& wi, const Vec3f& h) const {
        const float cos_ih = dot(wi, h);
        if (cos_ih <= 0 || wi.z <= 0) return 0.0f;
        return G1(wi) * cos_ih * D(h) / wi.z;
    }

    bool is_anisotropic() const { return alpha_u != alpha_v; }

    // The roughness parameters a texture may give (ParamInfo::texture_slot; slot 0 is the
    // reflectance of the BSDFs that have one), and setting one to its value at a hit (clamped
    // as the constructor does).
    static constexpr int kSlotAlpha = 1, kSlotAlphaU = 2, kSlotAlphaV = 3;
    void set_texel(int slot, float a) {
        const float v = std::max(a, kMinAlpha);
        if (slot != kSlotAlphaV) alpha_u = v;
        if (slot != kSlotAlphaU) alpha_v = v;
    }

private:
    // Solves f(x) = 0 for increasing f on [lo, hi] (f(lo) <= 0 <= f(hi)) by Newton steps,
    // bisecting whenever a step would leave the bracket. f returns {value, derivative}.
    template <typename F>
    static double solve_increasing(F f, double lo, double hi, double x) {
        for (int i = 0; i < 100; ++i) {
            const auto [v, dv] = f(x);
            if (v == 0) return x;
            (v < 0 ? lo : hi) = x;
            double next = dv > 0 ? x - v / dv : 0.5 * (lo + hi);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            if (std::abs(next - x) <= 1e-12 * std::max(1.0, std::abs(x))) return next;
            x = next;
        }
        return x;
    }

    Vec3f sample_beckmann(const Vec3f& wi, const Vec2f& u) const {
        // Stretch to roughness 1; wi's azimuth phi and polar angle theta there.
        const Vec3f v = normalize(Vec3f(alpha_u * wi.x, alpha_v * wi.y, wi.z));
        const double sin_t = std::hypot(double(v.x), double(v.y));
        const double cos_phi = sin_t > 0 ? v.x / sin_t : 1.0, sin_phi = sin_t > 0 ? v.y / sin_t : 0.0;
        constexpr double kSqrtPi = 1.7724538509055160273, kBound = 6;  // erf(6) = 1 - 2e-17
        // y: erf(y) = 2 u.y - 1.
        const double uy = std::clamp(2.0 * u.y - 1.0, -1 + 1e-15, 1 - 1e-15);
        const double y = solve_increasing(
            [&](double t) { return std::pair{std::erf(t) - uy, 2 / kSqrtPi * std::exp(-t * t)}; }, -kBound, kBound, 0.0);
        // x: the CDF up to x of (c - t) exp(-t^2) is c sqrt(pi)/2 (1 + erf x) + exp(-x^2)/2,
        // c = cot theta; near normal incidence (c huge) x is Gaussian like y.
        double x;
        const double c = double(v.z) / sin_t;
        if (!(c < 1e6)) {
            const double ux = std::clamp(2.0 * u.x - 1.0, -1 + 1e-15, 1 - 1e-15);
            x = solve_increasing(
                [&](double t) { return std::pair{std::erf(t) - ux, 2 / kSqrtPi * std::exp(-t * t)}; }, -kBound, kBound, 0.0);
        } else {
            const auto cdf = [&](double t) { return c * kSqrtPi / 2 * (1 + std::erf(t)) + std::exp(-t * t) / 2; };
            const double hi = std::min(c, kBound), lo = std::min(-kBound, hi - 2 * kBound);
            const double target = double(u.x) * cdf(hi) + (1 - double(u.x)) * cdf(lo);
            x = solve_increasing([&](double t) { return std::pair{cdf(t) - target, (c - t) * std::exp(-t * t)}; }, lo, hi,
                                 std::clamp(0.0, lo, hi));
        }
        // Rotate back by phi, unstretch, and turn the slope into a normal.
        const double sx = alpha_u * (cos_phi * x - sin_phi * y), sy = alpha_v * (sin_phi * x + cos_phi * y);
        return normalize(Vec3f(float(-sx), float(-sy), 1.0f));
    }
};

// The parameters of a rough BSDF's microfacet distribution (isotropic ones have no alpha_u,
// alpha_v), and how they are read. `textured`: textures may give the roughness.
inline std::vector<ParamInfo> microfacet_params(bool anisotropic, bool textured) {
    const auto slot = [textured](int s) { return textured ? s : -1; };
    std::vector<ParamInfo> p = {
        {"distribution", ParamType::String, "beckmann", "microfacet distribution: beckmann or ggx"},
        {"alpha", ParamType::Float, "0.1", "roughness (0.01 is nearly a mirror, 1 very rough)", "",
         slot(MicrofacetDistribution::kSlotAlpha)},
    };
    if (anisotropic) {
        p.push_back({"alpha_u", ParamType::Float, "",
                     "roughness along the shading frame's tangent, dp/du (with alpha_v, instead of alpha; without uv the tangent follows from the normal alone)",
                     "alphaU", slot(MicrofacetDistribution::kSlotAlphaU)});
        p.push_back({"alpha_v", ParamType::Float, "", "roughness along the bitangent", "alphaV", slot(MicrofacetDistribution::kSlotAlphaV)});
    }
    return p;
}
inline const ParamInfo kSampleVisibleParam{"sample_visible", ParamType::Boolean, "true",
                                           "accepted for compatibility; visible normals are always sampled", "sampleVisible"};

inline MicrofacetDistribution read_microfacet(Properties& p, bool anisotropic) {
    MicrofacetType type = MicrofacetType::Beckmann;
    const std::string d = p.get_string("distribution");
    if (d == "ggx") type = MicrofacetType::GGX;
    else if (d != "beckmann") p.fail("distribution", fmt::format("unsupported distribution '{}'; supported: beckmann, ggx", d));
    const bool uv = p.has("alpha_u") || p.has("alpha_v") || p.has("alphaU") || p.has("alphaV");
    if (uv && !anisotropic) {
        for (const char* n : {"alpha_u", "alpha_v", "alphaU", "alphaV"})
            if (p.has(n)) p.fail(n, fmt::format("<bsdf type=\"{}\"> is isotropic: give alpha", p.plugin().type));
    }
    if (uv && p.has("alpha")) p.fail("alpha", "give either alpha or alpha_u and alpha_v, not both");
    if (uv && !(p.has("alpha_u") && p.has("alpha_v"))) p.fail("anisotropic roughness needs both alpha_u and alpha_v");
    const auto roughness = [&](const std::string& name) {
        const float a = p.get_float(name);
        if (p.has(name) && !(a >= 0 && a <= 10)) p.fail(name, fmt::format("{} must be between 0 and 10, got {}", name, a));
        return a;
    };
    if (uv) return MicrofacetDistribution(type, roughness("alpha_u"), roughness("alpha_v"));
    const float a = roughness("alpha");
    return MicrofacetDistribution(type, a, a);
}

}  // namespace pathlab
