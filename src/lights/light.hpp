// Light sources. A closed set of types dispatched with std::visit.
//
// sample(p, u) picks a direction wi from the reference point p towards the light and returns
// the radiance Le arriving along it (if unoccluded) with pdfW, the density of wi per unit
// solid angle. Delta lights (point, directional) return delta = true and pdfW = 1: they can
// only be reached by light sampling. Area lights sample points uniformly by area (pdfA = 1/A)
// and convert to solid angle here, pdfW = pdfA d^2 / cos(theta_light), so estimators only
// ever see solid-angle densities.
#pragma once

#include <optional>
#include <variant>

#include "core/sampling.hpp"
#include "core/vec.hpp"

namespace pathlab {

struct LightSample {
    Vec3f wi;               // unit direction from the reference point towards the light
    float distance = kInf;  // to the sampled point; kInf for lights at infinity
    Vec3f point, normal;    // sampled point and its surface normal (area lights only)
    Rgb Le;                 // radiance arriving along -wi; intensity / d^2 for a point light
    float pdfW = 0;         // solid-angle density of wi (1 for delta lights)
    bool delta = false;
};

// Isotropic point light: intensity I (W/sr per channel). Power 4 pi I.
struct PointLight {
    Vec3f position;
    Rgb intensity;

    std::optional<LightSample> sample(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        return LightSample{d / dist, dist, position, Vec3f(0.0f), intensity / dist2, 1.0f, true};
    }
    float power(float) const { return 4 * kPi * mean(intensity); }
};

// One-sided Lambertian emitter on a triangle: radiance L along its geometric normal side
// (the normal of the winding p0, p1, p2). Power pi L A.
struct TriangleLight {
    Vec3f p0, e1, e2;  // p1 = p0 + e1, p2 = p0 + e2
    Vec3f normal;      // unit geometric normal; emits into its hemisphere only
    float area = 0;
    Rgb radiance;

    TriangleLight(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Rgb& L)
        : p0(a), e1(b - a), e2(c - a), radiance(L) {
        const Vec3f n = cross(e1, e2);
        area = 0.5f * length(n);
        normal = area > 0 ? n / (2 * area) : Vec3f(0, 0, 1);
        if (!(area > 0)) radiance = Rgb(0.0f);  // a degenerate triangle has no power
    }
    std::optional<LightSample> sample(const Vec3f& p, Vec2f u) const {
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
        return LightSample{wi, dist, q, normal, radiance, area_to_solid_angle(1 / area, dist, cos_light), false};
    }
    // Solid-angle density with which sample(p) would produce the point q (normal n).
    float pdfW(const Vec3f& p, const Vec3f& q, const Vec3f& = {}) const {
        const Vec3f d = q - p;
        const float dist = length(d);
        return area_to_solid_angle(1 / area, dist, -dot(d / dist, normal));
    }
    // Radiance leaving the emitter towards direction w (unit, pointing away from it).
    Rgb emitted(const Vec3f& w) const { return dot(w, normal) > 0 ? radiance : Rgb(0.0f); }
    float power(float) const { return kPi * mean(radiance) * area; }
};

// One-sided Lambertian emitter on a sphere: radiance L on the side its normal points to
// (outwards, or inwards with flip_normals). Points are sampled uniformly by area
// (pdfA = 1 / (4 pi r^2)); those facing away from the reference point are rejected. Power
// pi L A.
struct SphereLight {
    Vec3f center;
    float radius = 1;
    bool inward = false;
    Rgb radiance;

    std::optional<LightSample> sample(const Vec3f& p, Vec2f u) const {
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
    float pdfW(const Vec3f& p, const Vec3f& q, const Vec3f& n) const {
        const Vec3f d = q - p;
        const float dist = length(d);
        return area_to_solid_angle(1 / area(), dist, -dot(d / dist, n));
    }
    float area() const { return 4 * kPi * radius * radius; }
    float power(float) const { return kPi * mean(radiance) * area(); }
};

// Constant environment: radiance L from every direction, sampled uniformly over the sphere.
// Its power is taken as that of a disk of the scene's bounding radius R: pi R^2 * pi L.
struct EnvironmentLight {
    Rgb radiance;

    std::optional<LightSample> sample(const Vec3f&, Vec2f u) const {
        return LightSample{square_to_uniform_sphere(u), kInf, Vec3f(0.0f), Vec3f(0.0f), radiance, uniform_sphere_pdf(), false};
    }
    float pdfW() const { return uniform_sphere_pdf(); }
    float power(float scene_radius) const { return kPi * scene_radius * scene_radius * kPi * mean(radiance); }
};

// Directional light (sun-like, infinitely far): irradiance E on a surface facing it,
// travelling along `direction`. Power pi R^2 E over the scene's bounding disk.
struct DirectionalLight {
    Vec3f direction;  // unit direction in which the light travels
    Rgb irradiance;

    std::optional<LightSample> sample(const Vec3f&, Vec2f) const {
        return LightSample{-direction, kInf, Vec3f(0.0f), Vec3f(0.0f), irradiance, 1.0f, true};
    }
    float power(float scene_radius) const { return kPi * scene_radius * scene_radius * mean(irradiance); }
};

using Light = std::variant<PointLight, TriangleLight, SphereLight, EnvironmentLight, DirectionalLight>;

// Radiance of a surface emitter (triangle or sphere), black for other lights.
inline Rgb surface_radiance(const Light& light) {
    if (const auto* t = std::get_if<TriangleLight>(&light)) return t->radiance;
    if (const auto* s = std::get_if<SphereLight>(&light)) return s->radiance;
    return Rgb(0.0f);
}
// Solid-angle density with which sampling the surface emitter `light` from p produces the
// point q with normal n (0 for other lights).
inline float surface_light_pdfW(const Light& light, const Vec3f& p, const Vec3f& q, const Vec3f& n) {
    if (const auto* t = std::get_if<TriangleLight>(&light)) return t->pdfW(p, q);
    if (const auto* s = std::get_if<SphereLight>(&light)) return s->pdfW(p, q, n);
    return 0.0f;
}

inline std::optional<LightSample> sample_light(const Light& light, const Vec3f& p, const Vec2f& u) {
    return std::visit([&](const auto& l) { return l.sample(p, u); }, light);
}
inline float light_power(const Light& light, float scene_radius) {
    return std::visit([&](const auto& l) { return l.power(scene_radius); }, light);
}

}  // namespace pathlab
