// Warps from the unit square to directions and points, each with the density it produces.
// Direction densities are per unit solid angle (pdfW); point densities per unit area (pdfA).
#pragma once

#include <cmath>

#include "core/vec.hpp"

namespace pathlab {

// Shirley-Chiu concentric map from [0,1)^2 to the unit disk (area-preserving up to pi).
inline Vec2f square_to_concentric_disk(const Vec2f& u) {
    const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0 && b == 0) return {0, 0};
    float r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi / 4) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2) - (kPi / 4) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

inline Vec3f square_to_uniform_sphere(const Vec2f& u) {
    const float z = 1.0f - 2.0f * u.x;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float uniform_sphere_pdf() { return 1.0f / (4.0f * kPi); }

inline Vec3f square_to_uniform_hemisphere(const Vec2f& u) {
    const float z = u.x;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_hemisphere_pdf(const Vec3f& w) { return w.z > 0 ? 1.0f / (2.0f * kPi) : 0.0f; }

// Directions uniformly inside the cone of half-angle acos(cos_max) around +z:
// pdfW = 1 / (2 pi (1 - cos_max)).
inline Vec3f square_to_uniform_cone(const Vec2f& u, float cos_max) {
    const float z = 1.0f - u.x * (1.0f - cos_max);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_cone_pdf(float cos_max) { return 1.0f / (2.0f * kPi * (1.0f - cos_max)); }

// Malley's method: project the concentric disk up to the hemisphere. pdfW = cos(theta) / pi.
inline Vec3f square_to_cosine_hemisphere(const Vec2f& u) {
    const Vec2f d = square_to_concentric_disk(u);
    const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}
inline float cosine_hemisphere_pdf(const Vec3f& w) { return w.z > 0 ? w.z * kInvPi : 0.0f; }

// Directions around +z with density proportional to cos^n: pdfW = (n + 1) / (2 pi) cos^n.
// Used for the Phong lobe, with +z the mirror direction. May return directions with z < 0
// only when rotated into a frame; here z >= 0 always.
inline Vec3f square_to_power_cosine(const Vec2f& u, float exponent) {
    const float z = std::pow(1.0f - u.x, 1.0f / (exponent + 1.0f));  // 1 - u avoids pow(0, .)
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float power_cosine_pdf(float cos_alpha, float exponent) {
    return cos_alpha > 0 ? (exponent + 1.0f) / (2.0f * kPi) * std::pow(cos_alpha, exponent) : 0.0f;
}

// Uniform barycentrics (b1, b2) on a triangle; the point is (1-b1-b2) p0 + b1 p1 + b2 p2.
// pdfA = 1 / area.
inline Vec2f square_to_uniform_triangle(const Vec2f& u) {
    const float su = std::sqrt(u.x);
    return {1.0f - su, u.y * su};
}

// Solid-angle density of a point sampled with density pdfA on a surface at distance `dist`
// whose normal makes cosine `cos_at_surface` with the connecting direction.
inline float area_to_solid_angle(float pdfA, float dist, float cos_at_surface) {
    return cos_at_surface > 0 ? pdfA * dist * dist / cos_at_surface : 0.0f;
}

// Balance heuristic weight for strategy a against strategy b (pdfs in the same measure).
inline float balance_heuristic(float pdf_a, float pdf_b) {
    return pdf_a > 0 ? pdf_a / (pdf_a + pdf_b) : 0.0f;
}
// Veach's power heuristic with beta = 2: pdf_a^2 / (pdf_a^2 + pdf_b^2).
inline float power_heuristic(float pdf_a, float pdf_b) {
    if (!(pdf_a > 0)) return 0.0f;
    const float r = pdf_b / pdf_a;  // as a ratio, so that large densities do not overflow
    return 1 / (1 + r * r);
}
// The weight of strategy a against b by one of the two.
inline float mis_heuristic(bool power, float pdf_a, float pdf_b) {
    return power ? power_heuristic(pdf_a, pdf_b) : balance_heuristic(pdf_a, pdf_b);
}

}  // namespace pathlab
