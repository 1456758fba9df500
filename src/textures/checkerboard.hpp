// checkerboard: two colours in a checker pattern of unit squares in uv (Mitsuba 3's
// `checkerboard`).
//
// XML (Mitsuba 3 names):
//   color0  rgb        the colour of the squares where both fractional parts of uv' are on
//                      the same side of 1/2                                      default 0.4
//   color1  rgb        the other squares                                         default 0.2
//   to_uv   transform  applied to uv first (e.g. <scale x="8" y="8"/> for 8 x 8 squares)
// So [0, 1]^2 holds 2 x 2 squares, color0 at its corners [0, 1/2]^2 and [1/2, 1]^2 (Mitsuba
// 3's eval()); the scalar value eval_1 swaps the colours, as Mitsuba 3's does
// (src/textures/checkerboard.cpp there). In Mitsuba the colours may be textures themselves;
// here they are constants.
#pragma once

#include "textures/texture_common.hpp"

namespace pathlab {

struct CheckerboardTexture {
    Rgb color0{0.4f}, color1{0.2f};
    UvTransform to_uv;

    Rgb eval(const Vec2f& uv) const { return on_color0(uv) ? color0 : color1; }
    // The scalar value swaps the colours, as Mitsuba 3's eval_1 does (its colour eval does not):
    // a float parameter given a checkerboard (a roughness, a blend weight, principled's metallic)
    // renders as in Mitsuba, whose principled render tests depend on it.
    float eval_1(const Vec2f& uv) const { return scalar_value(on_color0(uv) ? color1 : color0); }
    // Whether uv lies on a colour0 square: both fractional parts of uv' on the same side of 1/2.
    bool on_color0(const Vec2f& uv) const {
        const Vec2f t = to_uv.apply(uv);
        return (t.x - std::floor(t.x) > 0.5f) == (t.y - std::floor(t.y) > 0.5f);
    }
    // Piecewise constant: no gradient (so a bump map of it is flat).
    Vec2f eval_1_grad(const Vec2f&) const { return {0.0f, 0.0f}; }
};

}  // namespace pathlab
