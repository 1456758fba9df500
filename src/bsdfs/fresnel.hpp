// Fresnel reflectance of smooth interfaces: dielectric-dielectric (real indices) and
// dielectric-conductor (complex index eta + i k, per RGB channel), unpolarised light; the
// hemispherical average of the dielectric one; and the complex indices of a few metals.
// Formulas: pbrt (Pharr, Jakob, Humphreys), sections 8.2 (3rd ed.) / 9.3 (4th ed.).
#pragma once

#include <cmath>

#include "core/vec.hpp"

namespace pathlab {

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
inline float fresnel_dielectric(float cos_i, float eta) {
    float unused;
    return fresnel_dielectric(cos_i, eta, &unused);
}

// Reflectance of a conductor of relative complex index eta + i k (one channel) for light
// arriving at cosine cos_i (0 < cos_i <= 1) from the dielectric side.
inline float fresnel_conductor(float cos_i, float eta, float k) {
    const float c2 = cos_i * cos_i, s2 = 1 - c2;
    const float eta2 = eta * eta, k2 = k * k;
    const float t0 = eta2 - k2 - s2;
    const float a2b2 = std::sqrt(std::max(0.0f, t0 * t0 + 4 * eta2 * k2));  // a^2 + b^2
    const float a = std::sqrt(std::max(0.0f, 0.5f * (a2b2 + t0)));
    const float t1 = a2b2 + c2, t2 = 2 * cos_i * a;
    const float rs = (t1 - t2) / (t1 + t2);
    const float t3 = c2 * a2b2 + s2 * s2, t4 = t2 * s2;
    const float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (rs + rp);
}
inline Rgb fresnel_conductor(float cos_i, const Rgb& eta, const Rgb& k) {
    return {fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
            fresnel_conductor(cos_i, eta.z, k.z)};
}

// Hemispherical (cosine-weighted) average of the dielectric Fresnel reflectance,
//   Fdr(eta) = 2 * integral_0^1 F(mu, eta) mu dmu,
// for diffuse light arriving from the side of index eta_i, eta = eta_t / eta_i (so eta < 1 is
// the internal reflectance of a coating, total internal reflection included). Integrated
// numerically (midpoint rule in mu^2, uniform in projected solid angle); computed once when a
// material is built.
inline float fresnel_diffuse_reflectance(float eta, int steps = 4096) {
    double sum = 0;
    for (int i = 0; i < steps; ++i) {
        const double mu2 = (i + 0.5) / steps;  // d(mu^2) = 2 mu dmu
        sum += fresnel_dielectric(float(std::sqrt(mu2)), eta);
    }
    return float(sum / steps);
}

}  // namespace pathlab
