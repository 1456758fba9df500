// What every texture shares: the uv transform (`to_uv`), the scalar value of a colour, and the
// record of which texels a lookup read (for gradients with respect to texels).
//
// Conventions (Mitsuba 3's): a texture is looked up at the hit's surface coordinates uv, first
// mapped by its `to_uv`, an affine map of the plane (a 3x3 matrix; of a 4x4 <transform> the
// upper-left 2x2 block and the translation column are kept, as Mitsuba does). A scalar
// parameter (a roughness, an exponent) takes a texture's grey value where the texture is grey
// (every channel equal), else its Rec. 709 luminance.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "core/transform.hpp"
#include "core/vec.hpp"

namespace pathlab {

struct UvTransform {
    // uv' = (m[0][0] u + m[0][1] v + m[0][2], m[1][0] u + m[1][1] v + m[1][2])
    std::array<std::array<float, 3>, 2> m{{{1, 0, 0}, {0, 1, 0}}};

    static UvTransform from(const Transform& t) {
        UvTransform r;
        for (int i = 0; i < 2; ++i) r.m[size_t(i)] = {float(t.m[size_t(i)][0]), float(t.m[size_t(i)][1]), float(t.m[size_t(i)][3])};
        return r;
    }
    bool is_identity() const { return m == UvTransform().m; }
    Vec2f apply(const Vec2f& uv) const {
        return {m[0][0] * uv.x + m[0][1] * uv.y + m[0][2], m[1][0] * uv.x + m[1][1] * uv.y + m[1][2]};
    }
    // A gradient with respect to uv' as one with respect to uv (the transpose of the linear part).
    Vec2f pull_back(const Vec2f& g) const { return {m[0][0] * g.x + m[1][0] * g.y, m[0][1] * g.x + m[1][1] * g.y}; }
};

// The scalar value of a colour: its grey value, or its luminance when the channels differ.
inline float scalar_value(const Rgb& c) { return c.x == c.y && c.y == c.z ? c.x : luminance(c); }

// Which texels a lookup read and the weight of each in the result (value = sum of weight *
// texel, up to rounding): 4 for a bilinear lookup (the same texel may appear twice at a
// clamped edge), 1 for a nearest one, 0 for textures without texels. Indices are into the
// texture's texel array (row-major, top row first).
struct TexelFootprint {
    std::array<uint32_t, 4> index{};
    std::array<float, 4> weight{};
    int count = 0;
};

}  // namespace pathlab
