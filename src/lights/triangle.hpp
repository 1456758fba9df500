// One triangle of an area emitter (a shape with <emitter type="area">): a one-sided
// Lambertian emitter of radiance L on the side of its geometric normal (the normal of the
// winding p0, p1, p2). Power pi L A.
//
// A textured emitter (<texture name="radiance">, Mitsuba 3's spatially varying area light)
// radiates the texture's value at the uv interpolated from its corners' (uv0 at p0, ...);
// `radiance` is then the texture's mean over the triangle (Scene::build estimates it), which
// only weighs the triangle among lights (its power, the light tree's bounds).
//
// Incident sampling: a point uniformly by area (pdfA = 1 / A), converted to solid angle.
// Emission: the same point and a cosine-weighted direction around the normal
// (pdfW = cos / pi).
#pragma once

#include <optional>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"
#include "textures/texture.hpp"

namespace pathlab {

struct TriangleLight {
    Vec3f p0, e1, e2;  // p1 = p0 + e1, p2 = p0 + e2
    Vec3f normal;      // unit geometric normal; emits into its hemisphere only
    float area = 0;
    Rgb radiance;
    const Texture* texture = nullptr;  // a textured emitter's radiance (owned by the Scene)
    Vec2f uv0{0.0f, 0.0f}, uv1{0.0f, 0.0f}, uv2{0.0f, 0.0f};

    static constexpr uint32_t flags = kLightSurface;

    // The radiance at the surface point with texture coordinates uv.
    Rgb radiance_at(const Vec2f& uv) const { return texture ? texture->eval(SurfaceUv(uv)) : radiance; }
    // ... at the point p0 + e1 b.x + e2 b.y.
    Rgb radiance_at_barycentric(const Vec2f& b) const {
        return texture ? texture->eval(SurfaceUv(uv0 * (1 - b.x - b.y) + uv1 * b.x + uv2 * b.y)) : radiance;
    }

    TriangleLight(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Rgb& L)
        : p0(a), e1(b - a), e2(c - a), radiance(L) {
        const Vec3f n = cross(e1, e2);
        area = 0.5f * length(n);
        normal = area > 0 ? n / (2 * area) : Vec3f(0, 0, 1);
        if (!(area > 0)) radiance = Rgb(0.0f);  // a degenerate triangle has no power
    }
    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f u) const {
        if (!(area > 0)) return std::nullopt;
        const Vec2f b = square_to_uniform_triangle(u);
        const Vec3f q = p0 + e1 * b.x + e2 * b.y;
        const Vec3f d = q - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Vec3f wi = d / dist;
        const float cos_light = -dot(wi, normal);
        if (cos_light <= 0) return std::nullopt;  // the reference point is behind the emitter
        return LightSample{wi, dist, q, normal, radiance_at_barycentric(b), area_to_solid_angle(1 / area, dist, cos_light), false};
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
        const Vec2f b = square_to_uniform_triangle(u_pos);
        return EmissionSample{p0 + e1 * b.x + e2 * b.y, normal, d, radiance_at_barycentric(b), c, 1 / area, c * kInvPi};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f& n, const Vec3f& d, const SceneSphere&) const {
        const float c = dot(n, d);
        return {1 / area, c > 0 ? c * kInvPi : 0.0f};
    }
    float power(const SceneSphere&) const { return kPi * mean(radiance) * area; }
};

}  // namespace pathlab
