// One triangle of an area emitter (a shape with <emitter type="area">): a one-sided
// Lambertian emitter of radiance L on the side of its geometric normal (the normal of the
// winding p0, p1, p2). Power pi L A.
//
// Incident sampling: a point uniformly by area (pdfA = 1 / A), converted to solid angle.
// Emission: the same point and a cosine-weighted direction around the normal
// (pdfW = cos / pi).
#pragma once

#include <optional>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"

namespace pathlab {

struct TriangleLight {
    Vec3f p0, e1, e2;  // p1 = p0 + e1, p2 = p0 + e2
    Vec3f normal;      // unit geometric normal; emits into its hemisphere only
    float area = 0;
    Rgb radiance;

    static constexpr uint32_t flags = kLightSurface;

    TriangleLight(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Rgb& L)
        : p0(a), e1(b - a), e2(c - a), radiance(L) {
        const Vec3f n = cross(e1, e2);
        area = 0.5f * length(n);
        normal = area > 0 ? n / (2 * area) : Vec3f(0, 0, 1);
        if (!(area > 0)) radiance = Rgb(0.0f);  // a degenerate triangle has no power
    }
    Vec3f sample_point(Vec2f u) const {
        const Vec2f b = square_to_uniform_triangle(u);
        return p0 + e1 * b.x + e2 * b.y;
    }
    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f u) const {
        if (!(area > 0)) return std::nullopt;
        const Vec3f q = sample_point(u);
        const Vec3f d = q - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Vec3f wi = d / dist;
        const float cos_light = -dot(wi, normal);
        if (cos_light <= 0) return std::nullopt;  // the reference point is behind the emitter
        return LightSample{wi, dist, q, normal, radiance, area_to_solid_angle(1 / area, dist, cos_light), false};
    }
    // Solid-angle density with which sample_li(p) would produce the point q (normal n).
    float pdf_li(const Vec3f& p, const Vec3f& q, const Vec3f& = {}) const {
        const Vec3f d = q - p;
        const float dist = length(d);
        return area_to_solid_angle(1 / area, dist, -dot(d / dist, normal));
    }
    std::optional<EmissionSample> sample_emission(Vec2f u_pos, Vec2f u_dir, const SceneSphere&) const {
        if (!(area > 0)) return std::nullopt;
        // The density from the world direction, exactly as pdf_emission() computes it.
        const Vec3f d = Frame(normal).to_world(square_to_cosine_hemisphere(u_dir));
        const float c = dot(normal, d);
        if (!(c > 0)) return std::nullopt;
        return EmissionSample{sample_point(u_pos), normal, d, radiance, c, 1 / area, c * kInvPi};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f& n, const Vec3f& d, const SceneSphere&) const {
        const float c = dot(n, d);
        return {1 / area, c > 0 ? c * kInvPi : 0.0f};
    }
    // Radiance leaving the emitter towards direction w (unit, pointing away from it).
    Rgb emitted(const Vec3f& w) const { return dot(w, normal) > 0 ? radiance : Rgb(0.0f); }
    float power(const SceneSphere&) const { return kPi * mean(radiance) * area; }
};

}  // namespace pathlab
