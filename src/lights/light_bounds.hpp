// What a light, or a group of lights, can send towards a point: the bounds of the light BVH
// (Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
// Splitting"). A box around the emitters, a cone holding every emitter's normal (axis w,
// half-angle theta_o), how far emission spreads around a normal (theta_e: pi/2 for a surface's
// cosine lobe, 0 for a spot's beam, whose cone is theta_o) and the total power phi.
//
// importance(p, n) (of LightBounds4, four groups at once) estimates, up to a common factor, the
// power that can arrive at p on a surface with normal n (n = 0: a point in a medium, no cosine there):
// phi cos(theta') / d^2, where d is the distance to the box's centre (no less than its bounding
// sphere's radius, twice that for a single emitter) and theta' the smallest angle between an
// emitter's normal and the direction to p that the box and the cones allow; times the receiver's
// cosine bound. It is 0 only where no emitter of the group can send light; the light sampler
// chooses between groups in proportion to it.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/float4.hpp"
#include "core/vec.hpp"
#include "lights/light.hpp"

namespace pathlab {

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
};

// The bounds of up to four groups side by side, lane k for group k (a node of the light tree holds
// its children's): what importance(p, n) reads, so that one pass of 4-wide arithmetic
// (core/float4.hpp) bounds all four. An empty lane has phi 0 and importance 0.
struct LightBounds4 {
    float cx[4]{}, cy[4]{}, cz[4]{}, radius[4]{};
    float wx[4]{}, wy[4]{}, wz[4]{}, phi[4]{};
    float cos_o[4]{}, sin_o[4]{}, cos_e[4]{};
    float inv_near2[4]{};  // 1 / (the squared distance below which importance stops growing)
    float two_sided[4]{};  // 1 or 0

    void set(int k, const LightBounds& b) {
        cx[k] = b.centre.x, cy[k] = b.centre.y, cz[k] = b.centre.z, radius[k] = b.radius;
        wx[k] = b.w.x, wy[k] = b.w.y, wz[k] = b.w.z, phi[k] = b.phi;
        cos_o[k] = b.cos_o, sin_o[k] = b.sin_o, cos_e[k] = b.cos_e;
        inv_near2[k] = 1 / std::max(b.near * b.radius * b.radius, 1e-20f);
        two_sided[k] = b.two_sided ? 1.0f : 0.0f;
    }

    // The four importances at p, on a surface with normal n (n = 0: in a medium). Every sine and
    // cosine is kept multiplied by the distance d to the centre (d cos theta_w = d.w,
    // d sin theta_w = sqrt(d^2 - (d.w)^2), d cos theta_b = sqrt(d^2 - r^2), d sin theta_b = r), so
    // that the four square roots and the one division (1 / d^2) do not wait for each other.
    Float4 importance(const Vec3f& p, const Vec3f& n) const {
        const Float4 phi4 = Float4::load(phi), radius4 = Float4::load(radius);
        const Float4 dx = Float4(p.x) - Float4::load(cx), dy = Float4(p.y) - Float4::load(cy), dz = Float4(p.z) - Float4::load(cz);
        const Float4 dd = dx * dx + dy * dy + dz * dz, r2 = radius4 * radius4;
        // Inside the bounding sphere every direction is possible: the distance is clamped to its radius.
        const Float4 inv_near2_4 = Float4::load(inv_near2);
        const Float4 inside = min(phi4 * inv_near2_4, Float4(1e30f));
        // Outside it (dd > r^2; what follows is discarded in the lanes inside).
        const Float4 zero(0.0f), one(1.0f);
        const Float4 inv_dd = one / dd;
        Float4 dw = Float4::load(wx) * dx + Float4::load(wy) * dy + Float4::load(wz) * dz;  // d cos theta_w
        dw = select(Float4::load(two_sided) > zero, abs(dw), dw);
        const Float4 d = sqrt(dd), dsin_w = sqrt(max(zero, dd - dw * dw)), dcos_b = sqrt(max(zero, dd - r2));
        // theta_x = max(0, theta_w - theta_o), then theta' = max(0, theta_x - theta_b), as cosines
        // (d cos theta_x, d sin theta_x; cos theta' = (d cos theta_x d cos theta_b + d sin theta_x r) / d^2).
        const Float4 cos_o4 = Float4::load(cos_o), sin_o4 = Float4::load(sin_o);
        const Float4 dcos_x = dw * cos_o4 + dsin_w * sin_o4, dsin_x = dsin_w * cos_o4 - dw * sin_o4;
        const Float4 cos_p = select((dw < d * cos_o4) & (dcos_x < dcos_b), (dcos_x * dcos_b + dsin_x * radius4) * inv_dd, one);
        Float4 outside = min(phi4 * max(cos_p, zero) * min(inv_dd, inv_near2_4), Float4(1e30f));
        if (n.x != 0 || n.y != 0 || n.z != 0) {  // the receiver's cosine, bounded the same way
            const Float4 dn = dx * Float4(n.x) + dy * Float4(n.y) + dz * Float4(n.z);
            const Float4 dcos_i = abs(dn), dsin_i = sqrt(max(zero, dd - dn * dn));
            outside = outside * select(dcos_i < dcos_b, (dcos_i * dcos_b + dsin_i * radius4) * inv_dd, one);
        }
        // theta' > theta_e: outside every emitter's lobe.
        outside = select(cos_p < Float4::load(cos_e), zero, outside);
        return select(phi4 > zero, select(dd <= r2, inside, outside), zero);
    }
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
