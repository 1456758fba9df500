// Delta BSDFs: a perfect mirror and a smooth dielectric (glass). Their lobes are Dirac deltas,
// so eval() and pdf() are zero for every direction and only sample() produces light
// transport. A sample's `f` and `pdfW` are the coefficients of the deltas, so f |cos| / pdfW
// is the path weight. Conventions as in material.hpp: local frame, normal +z, `wi` towards the
// camera side, `wo` the sampled direction, light flows from wo to wi.
#pragma once

#include <cmath>
#include <optional>

#include "scene/phong.hpp"

namespace pathlab {

// A perfect mirror with reflectance R (Mitsuba's "conductor" reduced to a mirror).
struct MirrorMaterial {
    Rgb reflectance{1.0f};

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f) const {
        if (wi.z <= 0) return std::nullopt;
        const Vec3f wo(-wi.x, -wi.y, wi.z);
        return BsdfSample{wo, reflectance / wo.z, 1.0f, true};
    }
};

// Unpolarised Fresnel reflectance at a smooth interface. cos_i > 0 is on the side of index
// eta_i; eta = eta_t / eta_i. Returns 1 under total internal reflection; *cos_t receives the
// cosine of the refracted direction (positive).
inline float fresnel_dielectric(float cos_i, float eta, float* cos_t) {
    const float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1) {
        *cos_t = 0;
        return 1.0f;
    }
    const float ct = std::sqrt(1 - sin2_t);
    *cos_t = ct;
    const float rs = (cos_i - eta * ct) / (cos_i + eta * ct);
    const float rp = (eta * cos_i - ct) / (eta * cos_i + ct);
    return 0.5f * (rs * rs + rp * rp);
}

// Smooth dielectric interface between an exterior (index ext_ior, the side the normal points
// to) and an interior (int_ior). Reflection is chosen with probability F (Fresnel), refraction
// with 1 - F. Radiance keeps L / eta^2 invariant across the interface, so a refracted sample
// carries the weight (eta_wi / eta_wo)^2 (indices on the sides of wi and wo); a path that
// enters and leaves a body picks up factors that cancel.
struct DielectricMaterial {
    float int_ior = 1.5046f;  // Mitsuba's default (BK7 glass)
    float ext_ior = 1.000277f;

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        const bool outside = wi.z > 0;
        const float eta_wi = outside ? ext_ior : int_ior, eta_other = outside ? int_ior : ext_ior;
        const float cos_i = std::abs(wi.z);
        float cos_t = 0;
        const float F = fresnel_dielectric(cos_i, eta_other / eta_wi, &cos_t);
        if (u.x < F) {
            const Vec3f wo(-wi.x, -wi.y, wi.z);
            return BsdfSample{wo, Rgb(F / cos_i), F, true};
        }
        // Refraction: wo on the other side, tangential part scaled by eta_wi / eta_other.
        const float r = eta_wi / eta_other;
        const Vec3f wo(-wi.x * r, -wi.y * r, outside ? -cos_t : cos_t);
        const float scale = r * r;  // (eta_wi / eta_wo)^2
        return BsdfSample{wo, Rgb((1 - F) * scale / cos_t), 1 - F, true};
    }
};

}  // namespace pathlab
