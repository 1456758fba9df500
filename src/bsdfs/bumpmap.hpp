// bumpmap: a BSDF whose shading frame is that of the surface displaced by a height texture
// (Mitsuba 3's `bumpmap`).
//
// XML: <bsdf type="bumpmap"> wraps exactly one BSDF (nested, or <ref id>) and one texture of
// any name (nested <texture>, or <ref id>), the height h (its scalar value: grey, or luminance);
//   scale  float  multiplies the height's gradient                                   default 1
// The shading normal is that of p + scale h(u, v) n: n' = normalize(dp'/du x dp'/dv), dp'/du =
// dp/du + (scale dh/du - n.dp/du) n (and v), the change of n itself neglected
// (material_textures.hpp). Only h's variations matter; a constant height is no bump. Heights
// are in the units of p per unit of h: on a shape whose dp/du is long (a large rectangle) the
// same texture bumps less. The texture's gradient is that of its bilinear interpolant (zero
// for nearest lookups and checkerboards). flip_invalid_normals and use_shadowing_function as
// for normalmap (normalmap.hpp).
#pragma once

#include "bsdfs/normalmap.hpp"
#include "core/properties.hpp"

namespace pathlab {

inline const PluginInfo& bumpmap_plugin() {
    static const PluginInfo info{"bsdf", "bumpmap",
                                 "tilts the shading frame of one nested BSDF as the surface displaced by a height texture would be",
                                 [] {
                                     std::vector<ParamInfo> params{{"scale", ParamType::Float, "1", "multiplies the height texture's gradient"}};
                                     for (ParamInfo& p : bump_rule_params()) params.push_back(std::move(p));
                                     return params;
                                 }()};
    return info;
}

}  // namespace pathlab
