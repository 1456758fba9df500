// normalmap: a BSDF whose shading normal follows a texture (Mitsuba 3's `normalmap`).
//
// XML: <bsdf type="normalmap"> wraps exactly one BSDF (nested, or <ref id>) and one texture,
// named `normalmap` (nested <texture name="normalmap">, or <ref name="normalmap" id>). Its RGB
// value c in [0, 1]^3 is the normal 2 c - 1 in the tangent frame (s along dp/du, t = n x s, n
// the shading normal; material_textures.hpp). The texture should be read with raw = true
// (normal maps are linear data, not sRGB colours). A normal map of (0.5, 0.5, 1) everywhere is
// the unperturbed frame. It may wrap twosided or be wrapped by it: either way the back of the
// surface is the same tilted surface seen from behind (material.hpp).
//   flip_invalid_normals    boolean  mirror a tilted normal that the incoming direction sees
//                                    from behind about the shading normal    default true
//   use_shadowing_function  boolean  Conty Estevez et al.'s shadowing term on the outgoing
//                                    direction                               default true
// Both are Mitsuba 3's (and its defaults); they make the BSDF non-reciprocal, so the light-path
// integrators refuse them: set both false for the reciprocal model (material_textures.hpp).
#pragma once

#include "core/properties.hpp"

namespace pathlab {

// normalmap's and bumpmap's two options of Mitsuba 3.
inline std::vector<ParamInfo> bump_rule_params() {
    return {{"flip_invalid_normals", ParamType::Boolean, "true",
             "mirror a tilted normal that the incoming direction sees from behind about the shading normal (not reciprocal: light-path "
             "integrators refuse it)"},
            {"use_shadowing_function", ParamType::Boolean, "true",
             "multiply by Conty Estevez et al. 2019's shadowing term of the outgoing direction (not reciprocal: light-path integrators "
             "refuse it)"}};
}

inline const PluginInfo& normalmap_plugin() {
    static const PluginInfo info{"bsdf", "normalmap",
                                 "tilts the shading normal of one nested BSDF by a texture named normalmap (RGB 2c - 1 in the tangent frame)",
                                 bump_rule_params()};
    return info;
}

}  // namespace pathlab
