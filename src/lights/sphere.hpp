// An emitting sphere (<shape type="sphere"> with <emitter type="area">): a one-sided
// Lambertian emitter of radiance L on the side its normal points to (outwards, or inwards
// with flip_normals). Power pi L A.
//
// Incident sampling: points uniformly by area (pdfA = 1 / (4 pi r^2)); those facing away from
// the reference point are rejected. Emission: the same point and a cosine-weighted direction
// around its normal.
#pragma once

#include <optional>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"

namespace pathlab {

struct SphereLight {
    Vec3f center;
    float radius = 1;
    bool inward = false;
    Rgb radiance;

    static constexpr uint32_t flags = kLightSurface;

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f u) const {
        const Vec3f outward = square_to_uniform_sphere(u);
        const Vec3f n = inward ? -outward : outward;
        const Vec3f q = center + outward * radius;
        const Vec3f d = q - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Vec3f wi = d / dist;
        const float cos_light = -dot(wi, n);
        if (cos_light <= 0) return std::nullopt;
        return LightSample{wi, dist, q, n, radiance, area_to_solid_angle(1 / area(), dist, cos_light), false};
    }
    float pdf_li(const Vec3f& p, const Vec3f& q, const Vec3f& n) const {
        const Vec3f d = q - p;
        const float dist = length(d);
        return area_to_solid_angle(1 / area(), dist, -dot(d / dist, n));
    }
    std::optional<EmissionSample> sample_emission(Vec2f u_pos, Vec2f u_dir, const SceneSphere&) const {
        const Vec3f outward = square_to_uniform_sphere(u_pos);
        const Vec3f n = inward ? -outward : outward;
        // The density from the world direction, exactly as pdf_emission() computes it.
        const Vec3f d = Frame(n).to_world(square_to_cosine_hemisphere(u_dir));
        const float c = dot(n, d);
        if (!(c > 0)) return std::nullopt;
        return EmissionSample{center + outward * radius, n, d, radiance, c, 1 / area(), c * kInvPi};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f& n, const Vec3f& d, const SceneSphere&) const {
        const float c = dot(n, d);
        return {1 / area(), c > 0 ? c * kInvPi : 0.0f};
    }
    float area() const { return 4 * kPi * radius * radius; }
    float power(const SceneSphere&) const { return kPi * mean(radiance) * area(); }
};

}  // namespace pathlab
