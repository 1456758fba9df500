// Rays and the robust spawning of secondary rays from surfaces.
#pragma once

#include <bit>
#include <cstdint>

#include "core/vec.hpp"

namespace pathlab {

// Rays start at t = 0; secondary rays avoid self-intersection by offsetting their origin
// off the surface (offset_ray_origin), never by a scene-dependent epsilon on t.
struct Ray {
    Vec3f o;
    Vec3f d;  // need not be unit length for shadow segments; t is in units of |d|
    float tmax = kInf;
};

// Moves a point off its surface along the geometric normal n (oriented towards the side the
// new ray leaves from) by an amount proportional to the point's magnitude: a fixed number of
// float ulps per coordinate, or a tiny absolute offset near the origin (Waechter & Binder,
// "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, 2019).
inline Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n) {
    constexpr float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
    Vec3f out;
    for (int i = 0; i < 3; ++i) {
        const auto of = static_cast<int32_t>(kIntScale * n[i]);
        const float moved = std::bit_cast<float>(std::bit_cast<int32_t>(p[i]) + (p[i] < 0 ? -of : of));
        out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : moved;
    }
    return out;
}

// A ray leaving the surface point p (geometric normal ng) in direction d.
inline Ray spawn_ray(const Vec3f& p, const Vec3f& ng, const Vec3f& d) {
    return Ray{offset_ray_origin(p, dot(d, ng) >= 0 ? ng : -ng), d, kInf};
}

// A shadow segment from surface point p (normal ng) to point q. If q lies on a surface
// (normal nq non-zero) it is offset too, so neither end can hit its own surface.
inline Ray spawn_segment(const Vec3f& p, const Vec3f& ng, const Vec3f& q, const Vec3f& nq) {
    const Vec3f to_q = q - p;
    const Vec3f from = offset_ray_origin(p, dot(to_q, ng) >= 0 ? ng : -ng);
    const Vec3f to = is_black(nq) ? q : offset_ray_origin(q, dot(to_q, nq) <= 0 ? nq : -nq);
    return Ray{from, to - from, 1.0f - 1e-4f};
}

}  // namespace pathlab
