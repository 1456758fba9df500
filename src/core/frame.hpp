// Orthonormal frame around a unit normal; local coordinates have the normal as +z.
#pragma once

#include "core/vec.hpp"

namespace pathlab {

struct Frame {
    Vec3f s, t, n;

    Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
    // Branchless construction of a basis from one unit vector (Duff et al. 2017).
    explicit Frame(const Vec3f& normal) : n(normal) {
        const float sign = std::copysign(1.0f, n.z);
        const float a = -1.0f / (sign + n.z);
        const float b = n.x * n.y * a;
        s = Vec3f(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3f(b, sign + n.y * n.y * a, -n.y);
    }
    Vec3f to_local(const Vec3f& w) const { return {dot(w, s), dot(w, t), dot(w, n)}; }
    Vec3f to_world(const Vec3f& w) const { return s * w.x + t * w.y + n * w.z; }
};

}  // namespace pathlab
