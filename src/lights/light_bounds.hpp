// What a light, or a group of lights, can send towards a point: the bounds of the light BVH
// (Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
// Splitting"). A box around the emitters, a cone holding every emitter's normal (axis w,
// half-angle theta_o), how far emission spreads around a normal (theta_e: pi/2 for a surface's
// cosine lobe, 0 for a spot's beam, whose cone is theta_o) and the total power phi.
//
// importance(p, n) (of CompactLightBounds) estimates, up to a common factor, the power that can
// arrive at p on a surface with normal n (n = 0: a point in a medium, no cosine there):
// phi cos(theta') / d^2, where d is the distance to the box's centre (no less than its bounding
// sphere's radius, twice that for a single emitter) and theta' the smallest angle between an
// emitter's normal and the direction to p that the box and the cones allow; times the receiver's
// cosine bound. It is 0 only where no emitter of the group can send light; the light sampler
// chooses between groups in proportion to it.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.hpp"
#include "lights/light.hpp"

namespace pathlab {

// The part of a group's bounds that importance(p, n) reads (LightBounds::compact()): what the
// light tree keeps per node after it is built, 52 bytes.
struct CompactLightBounds {
    Vec3f centre{0.0f};
    float radius = 0;
    Vec3f w{0, 0, 1};
    float phi = 0;
    float cos_o = 1, sin_o = 0, cos_e = 1;
    float near = 1;
    bool two_sided = false;

    float importance(const Vec3f& p, const Vec3f& n) const {
        if (!(phi > 0)) return 0.0f;
        const Vec3f d = p - centre;
        const float dd = dot(d, d), r2 = radius * radius;
        // Inside the bounding sphere every direction is possible: the distance is clamped to its radius.
        if (dd <= r2) return std::min(phi / std::max(near * r2, 1e-20f), 1e30f);
        const float inv_d = 1 / std::sqrt(dd);
        const Vec3f wi = d * inv_d;  // from the lights towards p
        // The half-angle theta_b the bounding sphere subtends at p.
        const float sin_b = radius * inv_d, cos_b = std::sqrt(std::max(0.0f, 1 - sin_b * sin_b));
        // theta_x = max(0, theta_w - theta_o), then theta' = max(0, theta_x - theta_b), as cosines.
        float cos_w = dot(w, wi);
        if (two_sided) cos_w = std::abs(cos_w);
        float cos_p = 1;
        if (cos_w < cos_o) {
            const float sin_w = std::sqrt(std::max(0.0f, 1 - cos_w * cos_w));
            const float cos_x = cos_w * cos_o + sin_w * sin_o, sin_x = sin_w * cos_o - cos_w * sin_o;
            if (cos_x < cos_b) cos_p = cos_x * cos_b + sin_x * sin_b;
        }
        if (cos_p < cos_e) return 0.0f;  // theta' > theta_e: outside every emitter's lobe
        float importance = std::min(phi * std::max(cos_p, 0.0f) / std::max(dd, near * r2), 1e30f);
        if (n.x != 0 || n.y != 0 || n.z != 0) {
            const float cos_i = std::abs(dot(wi, n));
            if (cos_i < cos_b) importance *= cos_i * cos_b + std::sqrt(std::max(0.0f, 1 - cos_i * cos_i)) * sin_b;
        }
        return importance;
    }
};

struct LightBounds {
    Vec3f lo{kInf}, hi{-kInf};
    Vec3f w{0, 0, 1};
    float theta_o = 0, theta_e = 0;  // radians
    float cos_o = 1, sin_o = 0, cos_e = 1;  // of theta_o and theta_e (set_angles)
    float phi = 0;
    bool two_sided = false;
    Vec3f centre{0.0f};  // of the box, and the radius of its bounding sphere (seal)
    float radius = 0;
    // The distance below which importance stops growing, in radii squared: a single emitter's
    // (2 radii: closer than that its centre says little about where its light comes from);
    // a group's bounding sphere otherwise.
    float near = 1;

    void set_angles(float o, float e) {
        theta_o = std::min(o, kPi), theta_e = std::min(e, kPi);
        cos_o = std::cos(theta_o), sin_o = std::sin(theta_o), cos_e = std::cos(theta_e);
    }
    // After the box is final: its centre and bounding sphere.
    void seal() {
        if (lo.x > hi.x) return;
        centre = (lo + hi) * 0.5f;
        radius = 0.5f * length(hi - lo);
    }

    // What importance() reads, in one cache line (the sampler's tree nodes hold this).
    CompactLightBounds compact() const { return {centre, radius, w, phi, cos_o, sin_o, cos_e, near, two_sided}; }
};

// The bounds of a light at a finite position (not kLightInfinite).
inline LightBounds light_bounds(const Light& light, const SceneSphere& sphere) {
    LightBounds b;
    b.phi = std::max(0.0f, light_power(light, sphere));
    auto add = [&b](const Vec3f& p) { b.lo = min(b.lo, p), b.hi = max(b.hi, p); };
    if (const auto* t = std::get_if<TriangleLight>(&light)) {
        add(t->p0), add(t->p0 + t->e1), add(t->p0 + t->e2);
        b.w = t->normal;
        b.set_angles(0, kPi / 2);
    } else if (const auto* s = std::get_if<SphereLight>(&light)) {
        add(s->center - Vec3f(s->radius)), add(s->center + Vec3f(s->radius));
        b.set_angles(kPi, kPi / 2);
    } else if (const auto* spot = std::get_if<SpotLight>(&light)) {
        add(spot->position);
        b.w = spot->frame.n;
        b.set_angles(spot->cutoff, 0);
    } else if (const auto* projector = std::get_if<ProjectorLight>(&light)) {
        add(projector->position);
        b.w = projector->axes.n;
        b.set_angles(projector->half_angle(), 0);
    } else if (const auto* point = std::get_if<PointLight>(&light)) {
        add(point->position);
        b.set_angles(kPi, kPi / 2);
    } else if (const auto* ies = std::get_if<IesLight>(&light)) {
        add(ies->position);
        b.set_angles(kPi, kPi / 2);
    }
    b.near = 4;
    b.seal();
    return b;
}

// The smallest cone (of those this construction finds) holding the cones (a, theta_a) and (b, theta_b).
inline void unite_cones(Vec3f a, float theta_a, Vec3f b, float theta_b, Vec3f& w, float& theta) {
    if (theta_b > theta_a) std::swap(a, b), std::swap(theta_a, theta_b);
    const float cos_d = std::clamp(dot(a, b), -1.0f, 1.0f);
    const float theta_d = std::acos(cos_d);
    w = a, theta = kPi;
    if (std::min(theta_d + theta_b, kPi) <= theta_a) {
        theta = theta_a;
        return;
    }
    const float theta_o = 0.5f * (theta_a + theta_d + theta_b);
    if (theta_o >= kPi) return;
    const Vec3f perp = b - a * cos_d;  // towards b, perpendicular to a
    const float len = length(perp);
    if (!(len > 1e-6f)) return;
    const float theta_r = theta_o - theta_a;
    w = normalize(a * std::cos(theta_r) + perp * (std::sin(theta_r) / len));
    theta = theta_o;
}

inline LightBounds unite(const LightBounds& a, const LightBounds& b) {
    if (!(a.phi > 0)) {
        if (b.phi > 0) return b;
        LightBounds u{min(a.lo, b.lo), max(a.hi, b.hi)};
        u.seal();
        return u;
    }
    if (!(b.phi > 0)) return a;
    LightBounds u;
    u.lo = min(a.lo, b.lo), u.hi = max(a.hi, b.hi);
    u.phi = a.phi + b.phi;
    u.two_sided = a.two_sided || b.two_sided;
    float theta_o;
    unite_cones(a.w, a.theta_o, b.w, b.theta_o, u.w, theta_o);
    u.set_angles(theta_o, std::max(a.theta_e, b.theta_e));
    u.seal();
    return u;
}

}  // namespace pathlab
